//! The workspace's crates are its layers, and a lower one never names a higher one:
//! `sph-strategies` (scheduling) knows nothing of SPH, `sph-solver` (the physics) knows the
//! strategies and nothing of the harness, the report or the command line; `sph-harness`
//! (measuring and keeping) knows nothing of the report or the command line, `sph-report`
//! (words and pictures) nothing of the command line. Read from
//! `cargo metadata`, so a dependency added to the wrong Cargo.toml fails here.

use std::collections::BTreeMap;
use std::process::Command;

/// Each workspace crate's direct dependencies (normal and build, not dev), by name.
fn dependencies() -> BTreeMap<String, Vec<String>> {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".to_owned());
    let out = Command::new(cargo)
        .args([
            "metadata",
            "--format-version",
            "1",
            "--no-deps",
            "--offline",
        ])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("cargo metadata runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    json["packages"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| {
            let deps = p["dependencies"]
                .as_array()
                .unwrap()
                .iter()
                .filter(|d| d["kind"].is_null() || d["kind"] == "build")
                .map(|d| d["name"].as_str().unwrap().to_owned())
                .collect();
            (p["name"].as_str().unwrap().to_owned(), deps)
        })
        .collect()
}

/// `krate`'s dependencies that are not in `allowed`.
fn beyond(deps: &BTreeMap<String, Vec<String>>, krate: &str, allowed: &[&str]) -> Vec<String> {
    let own = deps
        .get(krate)
        .unwrap_or_else(|| panic!("{krate} is a workspace member"));
    own.iter()
        .filter(|d| !allowed.contains(&d.as_str()))
        .cloned()
        .collect()
}

#[test]
fn the_strategies_crate_depends_on_threads_only() {
    let deps = dependencies();
    // `nix` only for `sched_getcpu`: which CPU a `team` thread runs on (whereabouts.rs).
    let extra = beyond(
        &deps,
        "sph-strategies",
        &[
            "rayon",
            "crossbeam",
            "chili",
            "paralight",
            "thiserror",
            "nix",
        ],
    );
    assert!(extra.is_empty(), "sph-strategies depends on {extra:?}");
}

#[test]
fn the_solver_crate_depends_on_the_strategies_and_no_harness_report_or_cli_crate() {
    let deps = dependencies();
    let allowed = [
        "sph-strategies",
        "thiserror",
        "csv",
        "serde",
        "glam",
        "pulp",
    ];
    let extra = beyond(&deps, "sph-solver", &allowed);
    assert!(
        extra.is_empty(),
        "sph-solver depends on {extra:?}: the physics must not know the harness (bench-sph, \
         clap, plotters, indicatif, ...)"
    );
    assert!(deps["sph-solver"].contains(&"sph-strategies".to_owned()));
}

#[test]
fn no_workspace_crate_depends_on_the_binary_crate() {
    let deps = dependencies();
    let users: Vec<&String> = deps
        .iter()
        .filter(|(_, d)| d.iter().any(|n| n == "bench-sph"))
        .map(|(k, _)| k)
        .collect();
    assert!(users.is_empty(), "{users:?} depend on bench-sph");
}

#[test]
fn the_harness_depends_on_no_report_drawing_or_command_line_crate() {
    let deps = dependencies();
    let above = [
        "sph-report",
        "bench-sph",
        "clap",
        "plotters",
        "png",
        "gif",
        "ab_glyph",
        "minifb",
    ];
    let named: Vec<&str> = above
        .into_iter()
        .filter(|a| deps["sph-harness"].iter().any(|d| d == a))
        .collect();
    assert!(named.is_empty(), "sph-harness depends on {named:?}");
    assert!(deps["sph-harness"].contains(&"sph-solver".to_owned()));
}

#[test]
fn the_report_depends_on_the_harness_and_no_command_line_crate() {
    let deps = dependencies();
    let named: Vec<&String> = deps["sph-report"]
        .iter()
        .filter(|d| ["bench-sph", "clap"].contains(&d.as_str()))
        .collect();
    assert!(named.is_empty(), "sph-report depends on {named:?}");
    assert!(deps["sph-report"].contains(&"sph-harness".to_owned()));
}
