//! Records, at build time, what `bench-sph sweep` writes into meta.json about the build:
//! the compiler's version (`BENCH_SPH_RUSTC`) and the git commit of the source tree
//! (`BENCH_SPH_GIT_COMMIT`, with `-dirty` when tracked files had changes; "unknown" outside
//! a git checkout or without git).

use std::process::Command;

fn main() {
    let rustc = std::env::var("RUSTC").unwrap_or_else(|_| "rustc".to_owned());
    let rustc_version = output(Command::new(rustc).arg("--version"));
    println!(
        "cargo:rustc-env=BENCH_SPH_RUSTC={}",
        rustc_version.as_deref().unwrap_or("unknown")
    );
    println!("cargo:rustc-env=BENCH_SPH_GIT_COMMIT={}", git_commit());
    // Rerun when the commit or the tracked sources may have changed, including the
    // `strategies` crate (a change there alone would otherwise leave a stale commit). A path
    // that does not exist (no `.git`) makes Cargo rerun the script every build.
    for path in [
        ".git/HEAD",
        ".git/index",
        ".git/refs",
        "Cargo.toml",
        "build.rs",
        "src",
        "strategies",
        "benches",
        "tests",
        "assets",
    ] {
        println!("cargo:rerun-if-changed={path}");
    }
}

/// `git rev-parse HEAD`, plus `-dirty` when tracked files that go into the build differ from
/// it (measured results and reports in `results/` and `report/` do not change the program).
fn git_commit() -> String {
    let Some(commit) = output(Command::new("git").args(["rev-parse", "HEAD"])) else {
        return "unknown".to_owned();
    };
    let dirty = output(Command::new("git").args([
        "status",
        "--porcelain",
        "--untracked-files=no",
        "--",
        "Cargo.toml",
        "Cargo.lock",
        "build.rs",
        "src",
        "strategies",
        "assets",
    ]))
    .is_some_and(|s| !s.is_empty());
    if dirty {
        format!("{commit}-dirty")
    } else {
        commit
    }
}

/// The trimmed standard output of a command that succeeded.
fn output(cmd: &mut Command) -> Option<String> {
    let out = cmd.output().ok()?;
    if !out.status.success() {
        return None;
    }
    Some(String::from_utf8_lossy(&out.stdout).trim().to_owned())
}
