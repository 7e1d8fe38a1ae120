//! `sweep --shard I/K` and `bench-sph merge`, end to end through the binary: shards run as
//! separate processes one after another (never at once: on this 2-core machine that would
//! spoil the timings), merged, give exactly the unsharded plan's cells and trials; and every
//! refusal of the merge. Timings are the hidden `--fake-timings`, so nothing here is timed.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use crate::common::*;

fn merge_fails(dirs: &[PathBuf], out: &Path, needles: &[&str]) {
    let o = merge(dirs, out, &[]);
    assert!(!o.status.success(), "{}", stdout(&o));
    let err = stderr(&o);
    assert!(err.starts_with("Error: "), "{err}");
    assert_holds_all("stderr", &err, needles);
    no_panic(&o);
    assert!(
        !out.join("summary.csv").exists(),
        "a refused merge wrote files"
    );
}

/// Trial rows per cell key (strategy, cores, chunks) of a results directory.
fn trials_per_cell(dir: &Path) -> BTreeMap<String, usize> {
    let mut cells = BTreeMap::new();
    for r in rows(&dir.join("trials.csv")) {
        let key = format!("{} {} {}", r["strategy"], r["cores"], r["chunks"]);
        *cells.entry(key).or_default() += 1;
    }
    cells
}

#[test]
fn three_shards_run_one_after_another_merge_into_exactly_the_unsharded_plans_cells_and_trials() {
    let _alone = alone();
    let tmp = tempfile::tempdir().unwrap();
    let whole = tmp.path().join("whole");
    sweep_plan(&whole, "");
    let parts = three_shards(tmp.path());
    let merged = tmp.path().join("merged");
    let o = merge(&parts, &merged, &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stdout(&o).contains("7 of the plan's 7 cells"),
        "{}",
        stdout(&o)
    );

    assert_eq!(trials_per_cell(&merged), trials_per_cell(&whole));
    assert_eq!(trials_per_cell(&whole).len(), 7);
    let summary = rows(&merged.join("summary.csv"));
    assert_eq!(summary.len(), 7);
    assert!(
        summary
            .iter()
            .all(|r| r["trials"] == "2" && r["status"] == "ok")
    );
    // Each row names the shard whose seq it divides by; an unsharded sweep leaves it empty.
    assert!(
        summary
            .iter()
            .all(|r| ["1", "2", "3"].contains(&r["reference_shard"].as_str()))
    );
    assert!(
        rows(&whole.join("summary.csv"))
            .iter()
            .all(|r| r["reference_shard"].is_empty())
    );
    let references = rows(&merged.join("references.csv"));
    assert_eq!(references.len(), 3, "each shard measured the group's seq");
    assert!(references.iter().all(|r| r["strategy"] == "seq"));

    let meta = std::fs::read_to_string(merged.join("meta.json")).unwrap();
    let meta: serde_json::Value = serde_json::from_str(&meta).unwrap();
    assert_eq!(meta["status"], "complete");
    assert_eq!(meta["planned_cells"], 7);
    assert!(meta["params"].get("shard").is_none());
    assert_eq!(meta["merge"]["shards"].as_array().unwrap().len(), 3);
    assert_eq!(meta["sessions"].as_array().unwrap().len(), 3);
    let whole_meta = read_json(&whole.join("meta.json"));
    assert_eq!(meta["plan_fingerprint"], whole_meta["plan_fingerprint"]);

    let report = succeeds(tmp.path(), &["report", merged.to_str().unwrap()]);
    assert!(report.contains("REPORT.md"), "{report}");
    let md = std::fs::read_to_string(merged.join("REPORT.md")).unwrap();
    assert!(md.contains("is a merge of shards 1/3, 2/3, 3/3"), "{md}");
    assert!(!md.contains("Partial study"), "{md}");
}

#[test]
fn a_shard_records_its_part_and_the_plans_fingerprint_and_draws_no_charts() {
    let _alone = alone();
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("s");
    let o = sweep_into(&dir, &format!("{SHARDED_PLAN} --shard 2/3"));
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stdout(&o).contains("shard 2/3 of plan "), "{}", stdout(&o));
    assert!(
        stdout(&o).contains("3 cells of its 7 cells"),
        "{}",
        stdout(&o)
    );
    assert!(
        stdout(&o).contains("not drawn for shard 2/3"),
        "{}",
        stdout(&o)
    );
    let meta = read_json(&dir.join("meta.json"));
    assert_eq!(meta["params"]["shard"]["index"], 2);
    assert_eq!(meta["params"]["shard"]["count"], 3);
    assert_eq!(meta["plan_fingerprint"].as_str().unwrap().len(), 16);
    let summary = rows(&dir.join("summary.csv"));
    assert_eq!(summary[0]["strategy"], "seq");
    assert!(summary.iter().all(|r| r["reference_shard"] == "2"));
    // Its own report says it holds one shard.
    succeeds(tmp.path(), &["report", dir.to_str().unwrap()]);
    let md = std::fs::read_to_string(dir.join("REPORT.md")).unwrap();
    assert!(md.contains("**One shard**"), "{md}");
}

#[test]
fn a_shard_that_would_be_empty_or_a_malformed_shard_is_refused() {
    let _alone = alone();
    let (_tmp, dir) = scratch("s");
    let mut cmd = sweep_command(&dir, &format!("{SHARDED_PLAN} --shard 7/7"));
    cmd.env("NO_COLOR", "1");
    expect_failure(cmd, &["Error: ", "--shard 7/7", "at most 6 shards"]);
    assert!(!dir.join("summary.csv").exists());
    for bad in ["0/3", "4/3", "x"] {
        let cmd = sweep_command(&dir, &format!("{SHARDED_PLAN} --shard {bad}"));
        expect_failure(cmd, &["--shard", "expected I/K"]);
    }
}

#[test]
fn merging_refuses_missing_cells_unless_partial_and_then_the_report_says_so() {
    let _alone = alone();
    let tmp = tempfile::tempdir().unwrap();
    let parts = three_shards(tmp.path());
    let out = tmp.path().join("merged");
    let two = [parts[0].clone(), parts[2].clone()];
    merge_fails(
        &two,
        &out,
        &["missing", "not given: shard 2/3", "--allow-partial"],
    );

    let o = merge(&two, &out, &["--allow-partial"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("the merge is partial"),
        "{}",
        stderr(&o)
    );
    let meta = std::fs::read_to_string(out.join("meta.json")).unwrap();
    assert!(meta.contains("\"status\": \"partial\""), "{meta}");
    assert!(meta.contains("\"missing_cells\""), "{meta}");
    succeeds(tmp.path(), &["report", out.to_str().unwrap()]);
    let md = std::fs::read_to_string(out.join("REPORT.md")).unwrap();
    assert!(
        md.contains("Partial study") && md.contains("merge again"),
        "{md}"
    );
    // A merge is not a sweep to resume.
    fails_with(
        &["sweep", "--resume", out.to_str().unwrap()],
        &["is a merge of shards", "merge again"],
    );
}

#[test]
fn merging_refuses_repeats_other_plans_other_splits_and_directories_that_are_not_shards() {
    let _alone = alone();
    let tmp = tempfile::tempdir().unwrap();
    let parts = three_shards(tmp.path());
    let out = tmp.path().join("merged");

    let again = tmp.path().join("again");
    copy_dir(&parts[0], &again);
    let repeated = [parts[0].clone(), parts[1].clone(), parts[2].clone(), again];
    merge_fails(&repeated, &out, &["shard 1/3 is given twice"]);

    let other = tmp.path().join("other-plan");
    let o = sweep_into(&other, &format!("{SHARDED_PLAN} --shard 2/3 --seed 7"));
    assert!(o.status.success(), "{}", stderr(&o));
    let mixed = [parts[0].clone(), other, parts[2].clone()];
    merge_fails(&mixed, &out, &["different plans"]);

    let halves = tmp.path().join("half");
    let o = sweep_into(&halves, &format!("{SHARDED_PLAN} --shard 2/2"));
    assert!(o.status.success(), "{}", stderr(&o));
    merge_fails(&[parts[0].clone(), halves], &out, &["different splits"]);

    let whole = tmp.path().join("whole");
    sweep_plan(&whole, "");
    merge_fails(&[whole], &out, &["is not a shard"]);

    let shard_one = std::fs::read(parts[0].join("summary.csv")).unwrap();
    let o = merge(&parts, &parts[0], &["--force"]);
    assert!(!o.status.success());
    assert!(
        stderr(&o).contains("is one of the shards being merged"),
        "{}",
        stderr(&o)
    );
    assert_eq!(
        std::fs::read(parts[0].join("summary.csv")).unwrap(),
        shard_one
    );
}

#[test]
fn merging_refuses_shards_from_another_machine_or_another_build() {
    let _alone = alone();
    let tmp = tempfile::tempdir().unwrap();
    let parts = three_shards(tmp.path());
    let out = tmp.path().join("merged");

    let elsewhere = tmp.path().join("elsewhere");
    copy_dir(&parts[1], &elsewhere);
    set_in_meta(&elsewhere, |m| {
        m["machine"]["cpu_model"] = "Another CPU".into()
    });
    let mixed = [parts[0].clone(), elsewhere, parts[2].clone()];
    merge_fails(
        &mixed,
        &out,
        &["Another CPU", "a comparison, not a merge", "report A B"],
    );

    let rebuilt = tmp.path().join("rebuilt");
    copy_dir(&parts[1], &rebuilt);
    set_in_meta(&rebuilt, |m| m["git_commit"] = "0123456789ab".into());
    let mixed = [parts[0].clone(), rebuilt, parts[2].clone()];
    merge_fails(&mixed, &out, &["0123456789ab", "different builds"]);
}

#[test]
fn a_merge_never_replaces_existing_results_without_force() {
    let _alone = alone();
    let tmp = tempfile::tempdir().unwrap();
    let parts = three_shards(tmp.path());
    let out = tmp.path().join("merged");
    assert!(merge(&parts, &out, &[]).status.success());
    let before = std::fs::read(out.join("summary.csv")).unwrap();
    let o = merge(&parts, &out, &[]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("--force"), "{}", stderr(&o));
    assert_eq!(std::fs::read(out.join("summary.csv")).unwrap(), before);
    assert!(merge(&parts, &out, &["--force"]).status.success());
}

/// `scripts/<name>` of this repository, run by bash with the test's binary as `BENCH_SPH`.
fn script(name: &str) -> std::process::Command {
    let mut cmd = std::process::Command::new("bash");
    cmd.arg(
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("scripts")
            .join(name),
    )
    .env("BENCH_SPH", env!("CARGO_BIN_EXE_bench-sph"));
    cmd
}

#[test]
fn parallel_sweep_without_hosts_runs_the_shards_one_after_another_then_merges_and_reports() {
    let _alone = alone();
    let tmp = tempfile::tempdir().unwrap();
    let root = tmp.path().join("study");
    let mut cmd = script("parallel-sweep.sh");
    cmd.args(["-k", "3", "-o", root.to_str().unwrap(), "--"])
        .args(
            SHARDED_PLAN
                .split_whitespace()
                .filter(|&a| a != "--no-plots"),
        );
    let o = cmd.output().unwrap();
    assert!(o.status.success(), "{}\n{}", stdout(&o), stderr(&o));
    let merged = root.join("merged");
    let whole = tmp.path().join("whole");
    sweep_plan(&whole, "");
    assert_eq!(trials_per_cell(&merged), trials_per_cell(&whole));
    assert!(merged.join("REPORT.md").is_file());
    // Run again without -f or -r: refused, nothing replaced.
    let before = std::fs::read(merged.join("summary.csv")).unwrap();
    let mut again = script("parallel-sweep.sh");
    again
        .args(["-k", "3", "-o", root.to_str().unwrap(), "--"])
        .args(SHARDED_PLAN.split_whitespace());
    let o = again.output().unwrap();
    assert!(!o.status.success());
    assert!(
        stderr(&o).contains("already holds a sharded sweep"),
        "{}",
        stderr(&o)
    );
    assert_eq!(std::fs::read(merged.join("summary.csv")).unwrap(), before);
}

#[test]
fn the_slurm_script_submits_an_array_of_shards_and_a_merge_that_waits_for_it() {
    let tmp = tempfile::tempdir().unwrap();
    let root = tmp.path().join("study");
    let mut cmd = script("slurm-sweep.sh");
    cmd.env("SBATCH", "echo")
        .args(["-k", "4", "-o", root.to_str().unwrap(), "--"])
        .args(["--cores", "1..2", "--n", "60", "--steps", "3"]);
    let o = cmd.output().unwrap();
    assert!(o.status.success(), "{}\n{}", stdout(&o), stderr(&o));
    let out = format!("{}{}", stdout(&o), stderr(&o));
    assert_holds_all(
        "the dry run",
        &out,
        &[
            "--array=1-4",
            "--exclusive",
            "--dependency=afterok:",
            "shard-job.sh merge 4",
        ],
    );
    assert!(!root.exists(), "a dry run wrote {}", root.display());
}
