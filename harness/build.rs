//! Records, at build time, what `bench-sph sweep` writes into meta.json about the build:
//! the compiler's version (`BENCH_SPH_RUSTC`) and the git commit of the source tree
//! (`BENCH_SPH_GIT_COMMIT`, with `-dirty` when tracked files had changes; "unknown" outside
//! a git checkout or without git).
//!
//! Git runs with `--no-optional-locks`: a plain `git status` refreshes `.git/index`, which
//! would make the next build run this script (and recompile the crates) again for nothing.
//!
//! The script watches every crate's sources, not only this one's: the commit it records
//! must say `-dirty` when any of the binary's sources changed, so an edit of the command line
//! or the report reruns it and recompiles this crate too. Provenance over build time.

use std::path::{Path, PathBuf};
use std::process::Command;

/// The tracked paths, relative to the workspace's root, that go into the build: a change to
/// one of them marks the commit dirty (measured results and reports in `results/` and
/// `report/` do not change the program).
const BUILD_INPUTS: [&str; 8] = [
    "Cargo.toml",
    "Cargo.lock",
    "src",
    "solver",
    "strategies",
    "harness",
    "reporting",
    "assets",
];

/// The workspace's root: this crate's parent folder.
fn root() -> PathBuf {
    let manifest = std::env::var_os("CARGO_MANIFEST_DIR").unwrap_or_else(|| ".".into());
    let manifest = PathBuf::from(manifest);
    manifest
        .parent()
        .map_or(manifest.clone(), Path::to_path_buf)
}

fn main() {
    let rustc = std::env::var("RUSTC").unwrap_or_else(|_| "rustc".to_owned());
    let rustc_version = output(Command::new(rustc).arg("--version"));
    println!(
        "cargo:rustc-env=BENCH_SPH_RUSTC={}",
        rustc_version.as_deref().unwrap_or("unknown")
    );
    println!("cargo:rustc-env=BENCH_SPH_GIT_COMMIT={}", git_commit());
    // Rerun when the commit may have moved (HEAD, the branch it points to, packed refs) or
    // the build's inputs changed (dirty or clean); not when other refs move (a fetch). Git's
    // files are located by git itself, so a worktree (where `.git` is a file) works; only
    // existing paths are named, since a missing one makes Cargo rerun the script on every
    // build.
    let branch = git(&["symbolic-ref", "-q", "HEAD"]);
    let watched = ["HEAD", "packed-refs"]
        .map(str::to_owned)
        .into_iter()
        .chain(branch);
    let git_paths = watched.filter_map(|p| git(&["rev-parse", "--git-path", &p]));
    let root = root();
    for path in git_paths.chain(BUILD_INPUTS.map(str::to_owned)) {
        let path = root.join(path); // git's paths are relative to where it ran: the root
        if path.exists() {
            println!("cargo:rerun-if-changed={}", path.display());
        }
    }
}

/// `git rev-parse HEAD`, plus `-dirty` when [`BUILD_INPUTS`] differ from it.
fn git_commit() -> String {
    let Some(commit) = git(&["rev-parse", "HEAD"]) else {
        return "unknown".to_owned();
    };
    let status = ["status", "--porcelain", "--untracked-files=no", "--"];
    let dirty = git(&[&status[..], &BUILD_INPUTS[..]].concat()).is_some_and(|s| !s.is_empty());
    if dirty {
        format!("{commit}-dirty")
    } else {
        commit
    }
}

/// The trimmed standard output of `git ARGS`, run in the workspace's root without optional
/// locks, if it succeeded.
fn git(args: &[&str]) -> Option<String> {
    output(
        Command::new("git")
            .arg("-C")
            .arg(root())
            .arg("--no-optional-locks")
            .args(args),
    )
}

/// The trimmed standard output of a command that succeeded.
fn output(cmd: &mut Command) -> Option<String> {
    let out = cmd.output().ok()?;
    if !out.status.success() {
        return None;
    }
    Some(String::from_utf8_lossy(&out.stdout).trim().to_owned())
}
