//! `bench-sph sweep` driven through the built binary: the files and their columns, statistics
//! that agree exactly with the trial rows (under the hidden test-only `--fake-timings`),
//! interruption and `--resume`, and a clear `Error: ...` with a non-zero exit for bad input.
//! No test asserts a duration.

use std::collections::BTreeMap;
use std::path::Path;
use std::process::{Command, Output, Stdio};
use std::time::Duration;

mod common;
use common::{
    Row, assert_file_holds, assert_holds_all, bench_sph, fails_with, num, poll_until, rows, run,
    scratch, start, stderr, stdout, sweep_into,
};

const TRIAL_HEADER: &str = "strategy,neighbors,preset,n,steps,cores,chunks,particles_per_chunk,\
    trial,wall_s,cpu_s,checksum,status,reason,foreign_cpu_s,steal_s,load1,pin,passes_alone";
const SUMMARY_HEADER: &str = "strategy,neighbors,preset,n,steps,cores,chunks,particles_per_chunk,\
    trials,mean_s,stddev_s,min_s,median_s,max_s,cpu_mean_s,speedup,efficiency,outliers,\
    oversubscribed,checksum,status,reason,mean_ci_low_s,mean_ci_high_s,speedup_ci_low,\
    speedup_ci_high,foreign_cpu_mean_s,contended,reference_shard,pin,smt";

/// A tiny sweep: 1 seq cell + 3 strategies × 2 cores + 2 strategies × 2 cores × 2 chunks = 15.
const TINY: &[&str] = &[
    "sweep",
    "--n",
    "60",
    "--steps",
    "3",
    "--trials",
    "2",
    "--warmup",
    "1",
    "--cores",
    "1..2",
    "--chunks",
    "2,5",
    "--no-plots",
];
const TINY_CELLS: usize = 15;

/// Runs the tiny sweep (plus `extra`) into `dir` and expects success.
fn tiny_sweep(dir: &Path, extra: &[&str]) -> Output {
    let mut args = TINY.to_vec();
    args.extend(["--out", dir.to_str().unwrap()]);
    args.extend(extra);
    let o = run(&args);
    assert!(
        o.status.success(),
        "{args:?}:\n{}\n{}",
        stdout(&o),
        stderr(&o)
    );
    o
}

fn header(path: &Path) -> String {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .next()
        .unwrap_or_default()
        .to_owned()
}

/// The columns that name a cell.
fn cell_key(row: &Row) -> String {
    [
        "strategy",
        "neighbors",
        "preset",
        "n",
        "steps",
        "cores",
        "chunks",
    ]
    .map(|c| row[c].as_str())
    .join("|")
}

/// Every cell's trial rows, by cell key.
fn trials_by_cell(trials: &[Row]) -> BTreeMap<String, Vec<&Row>> {
    let mut by_cell: BTreeMap<String, Vec<&Row>> = BTreeMap::new();
    for t in trials {
        by_cell.entry(cell_key(t)).or_default().push(t);
    }
    by_cell
}

/// Asserts one row per trial, numbered 1..=trials, for every summary row, and no other rows.
fn assert_one_row_per_trial(dir: &Path, trials_per_cell: usize, cells: usize) {
    let summary = rows(&dir.join("summary.csv"));
    let trials = rows(&dir.join("trials.csv"));
    assert_eq!(summary.len(), cells, "summary rows");
    let by_cell = trials_by_cell(&trials);
    assert_eq!(by_cell.len(), cells, "cells in trials.csv");
    let mut keys: Vec<String> = summary.iter().map(cell_key).collect();
    keys.sort();
    keys.dedup();
    assert_eq!(keys.len(), cells, "duplicate summary rows");
    for (key, rows) in &by_cell {
        let numbers: Vec<&str> = rows.iter().map(|r| r["trial"].as_str()).collect();
        let want: Vec<String> = (1..=trials_per_cell).map(|k| k.to_string()).collect();
        assert_eq!(numbers, want, "trials of {key}");
    }
}

// Test-side statistics, written independently of the crate's.
fn mean(xs: &[f64]) -> f64 {
    xs.iter().sum::<f64>() / xs.len() as f64
}

fn median(xs: &[f64]) -> f64 {
    let mut s = xs.to_vec();
    s.sort_by(f64::total_cmp);
    let k = s.len();
    if k % 2 == 1 {
        s[k / 2]
    } else {
        (s[k / 2 - 1] + s[k / 2]) / 2.0
    }
}

#[test]
fn a_tiny_sweep_writes_trials_summary_and_meta_with_the_documented_columns() {
    let (_tmp, dir) = scratch("r");
    let o = tiny_sweep(&dir, &[]);

    assert_eq!(header(&dir.join("trials.csv")), TRIAL_HEADER);
    assert_eq!(header(&dir.join("summary.csv")), SUMMARY_HEADER);
    assert_one_row_per_trial(&dir, 2, TINY_CELLS);

    let summary = rows(&dir.join("summary.csv"));
    assert!(
        summary
            .iter()
            .all(|r| r["status"] == "ok" && r["reason"].is_empty())
    );
    // One seq cell, at 1 core; strategies without chunks have one cell per cores value.
    let seq: Vec<&Row> = summary.iter().filter(|r| r["strategy"] == "seq").collect();
    assert_eq!(seq.len(), 1);
    assert_eq!(
        (seq[0]["cores"].as_str(), seq[0]["chunks"].as_str()),
        ("1", "")
    );
    assert_eq!(num(seq[0], "speedup"), 1.0);
    for strategy in ["rayon-iter", "rayon-spawn", "std-static"] {
        let cells: Vec<&Row> = summary
            .iter()
            .filter(|r| r["strategy"] == strategy)
            .collect();
        assert_eq!(cells.len(), 2, "{strategy}");
        assert!(
            cells
                .iter()
                .all(|r| r["chunks"].is_empty() && r["particles_per_chunk"].is_empty())
        );
    }
    for strategy in ["rayon-chunks", "crossbeam-pool"] {
        let cells: Vec<&Row> = summary
            .iter()
            .filter(|r| r["strategy"] == strategy)
            .collect();
        assert_eq!(cells.len(), 4, "{strategy}");
        for r in cells {
            let want = if r["chunks"] == "2" { "30" } else { "12" };
            assert_eq!(r["particles_per_chunk"], want, "{r:?}");
        }
    }
    // Every trial reproduced seq's checksum.
    let trials = rows(&dir.join("trials.csv"));
    assert!(
        trials
            .iter()
            .all(|t| t["checksum"] == seq[0]["checksum"] && t["checksum"].len() == 16)
    );
    assert!(
        trials
            .iter()
            .all(|t| num(t, "wall_s") > 0.0 && num(t, "cpu_s") >= 0.0)
    );

    let meta: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("meta.json")).unwrap()).unwrap();
    for field in ["cpu_model", "hardware_threads", "os", "kernel"] {
        assert!(
            !meta["machine"][field].is_null(),
            "machine.{field} in {meta}"
        );
    }
    for field in [
        "rustc",
        "version",
        "git_commit",
        "started_utc",
        "finished_utc",
        "command_line",
    ] {
        assert!(!meta[field].is_null(), "{field} in {meta}");
    }
    assert_eq!(meta["status"], "complete");
    assert_eq!(meta["params"]["n"], serde_json::json!([60]));
    assert_eq!(meta["params"]["cores"], serde_json::json!([1, 2]));
    assert_eq!(meta["params"]["chunks"], serde_json::json!([2, 5]));
    assert_eq!(meta["params"]["trials"], 2);
    assert_eq!(meta["params"]["warmup"], 1);
    assert_eq!(meta["params"]["strategies"].as_array().unwrap().len(), 6);
    assert!(
        meta["command_line"]
            .as_array()
            .unwrap()
            .iter()
            .any(|a| a == "--chunks")
    );

    assert_holds_all(
        "stdout",
        &stdout(&o),
        &[
            "15 cells",
            "1 warm-up + 2 trials",
            "estimated time",
            "Fastest cell per strategy",
            "trials.csv",
            "summary.csv",
            "meta.json",
        ],
    );
}

#[test]
fn summary_statistics_agree_exactly_with_the_trial_rows_under_fake_timings() {
    let (_tmp, dir) = scratch("r");
    // Seven items for three trials a cell: each cell gets a different slice of the list.
    let fake = "1:0.5,2:1,3:1.5,2:2,2:2,9:3,4:4";
    let mut args: Vec<&str> = TINY.to_vec();
    let at = args.iter().position(|a| *a == "--trials").unwrap();
    args[at + 1] = "3";
    args.extend(["--fake-timings", fake, "--out", dir.to_str().unwrap()]);
    let o = run(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains("--fake-timings"), "{}", stderr(&o));

    let summary = rows(&dir.join("summary.csv"));
    let trials = rows(&dir.join("trials.csv"));
    let by_cell = trials_by_cell(&trials);
    assert_eq!(summary.len(), TINY_CELLS);

    // The seq cell got 1, 2, 3 (CPU 0.5, 1, 1.5); the next cell 2, 2, 9.
    let seq = &summary[0];
    assert_eq!(seq["strategy"], "seq");
    for (column, want) in [
        ("mean_s", 2.0),
        ("stddev_s", 1.0),
        ("min_s", 1.0),
        ("median_s", 2.0),
        ("max_s", 3.0),
        ("cpu_mean_s", 1.0),
        ("speedup", 1.0),
        ("efficiency", 1.0),
        ("outliers", 0.0),
    ] {
        assert_eq!(num(seq, column), want, "seq {column}");
    }
    let second = &summary[1];
    assert_eq!(num(second, "mean_s"), 13.0 / 3.0);
    assert_eq!(num(second, "median_s"), 2.0);
    assert_eq!(num(second, "outliers"), 1.0, "9 is beyond 3 MAD (MAD = 0)");
    assert_eq!(num(second, "speedup"), 2.0 / (13.0 / 3.0));

    for s in &summary {
        let rows = &by_cell[&cell_key(s)];
        let walls: Vec<f64> = rows.iter().map(|r| num(r, "wall_s")).collect();
        let cpus: Vec<f64> = rows.iter().map(|r| num(r, "cpu_s")).collect();
        let m = mean(&walls);
        let sd = (walls.iter().map(|w| (w - m) * (w - m)).sum::<f64>() / (walls.len() - 1) as f64)
            .sqrt();
        let med = median(&walls);
        let mad = median(&walls.iter().map(|w| (w - med).abs()).collect::<Vec<_>>());
        let outliers = walls
            .iter()
            .filter(|w| (*w - med).abs() > 3.0 * mad)
            .count();
        let speedup = 2.0 / m;
        let cores = num(s, "cores");
        assert_eq!(num(s, "trials"), 3.0);
        assert_eq!(num(s, "mean_s"), m, "{s:?}");
        assert_eq!(num(s, "stddev_s"), sd, "{s:?}");
        assert_eq!(
            num(s, "min_s"),
            walls.iter().copied().fold(f64::INFINITY, f64::min)
        );
        assert_eq!(
            num(s, "max_s"),
            walls.iter().copied().fold(f64::NEG_INFINITY, f64::max)
        );
        assert_eq!(num(s, "median_s"), med, "{s:?}");
        assert_eq!(num(s, "cpu_mean_s"), mean(&cpus), "{s:?}");
        assert_eq!(num(s, "outliers"), outliers as f64, "{s:?}");
        assert_eq!(num(s, "speedup"), speedup, "{s:?}");
        assert_eq!(num(s, "efficiency"), speedup / cores, "{s:?}");
    }
    let meta = std::fs::read_to_string(dir.join("meta.json")).unwrap();
    assert!(meta.contains(fake), "fake timings are recorded: {meta}");
}

#[test]
fn a_sweep_stopped_midway_and_resumed_ends_with_exactly_one_row_per_trial() {
    let tmp = tempfile::tempdir().unwrap();
    let fake = ["--fake-timings", "1,2,3,4,5"];
    // The same sweep without interruption, to compare with.
    let whole = tmp.path().join("whole");
    tiny_sweep(&whole, &fake);

    let dir = tmp.path().join("r");
    let d = dir.to_str().unwrap();
    let mut args = TINY.to_vec();
    args.extend(["--out", d, "--stop-after-cells", "4"]);
    args.extend(fake);
    fails_with(
        &args,
        &["Error:", "interrupted", "4 of 15 cells", "--resume"],
    );
    assert_one_row_per_trial(&dir, 2, 4);
    let meta = std::fs::read_to_string(dir.join("meta.json")).unwrap();
    assert!(meta.contains("\"status\": \"interrupted\""), "{meta}");

    // A kill in the middle of writing the fifth cell (rayon-spawn at 2 cores): its first
    // trial row, then its second cut off mid-line.
    let trials_path = dir.join("trials.csv");
    let mut text = std::fs::read_to_string(&trials_path).unwrap();
    let last = text.lines().last().unwrap().to_owned();
    assert!(
        last.starts_with("rayon-spawn,all-pairs,seed,60,3,1,,,2,"),
        "{last}"
    );
    let partial = last.replacen(",60,3,1,,,2,", ",60,3,2,,,1,", 1);
    text.push_str(&format!(
        "{partial}\nrayon-spawn,all-pairs,seed,60,3,2,,,2,0.0"
    ));
    std::fs::write(&trials_path, text).unwrap();

    let o = run(&["sweep", "--resume", d, "--no-plots"]);
    assert!(o.status.success(), "{}\n{}", stdout(&o), stderr(&o));
    assert!(
        stdout(&o).contains("4 finished cells kept"),
        "{}",
        stdout(&o)
    );
    assert_one_row_per_trial(&dir, 2, TINY_CELLS);
    // Same parameters, same fake times: the same files as the uninterrupted sweep.
    for file in ["trials.csv", "summary.csv"] {
        assert_eq!(
            std::fs::read_to_string(dir.join(file)).unwrap(),
            std::fs::read_to_string(whole.join(file)).unwrap(),
            "{file}"
        );
    }
    let meta: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("meta.json")).unwrap()).unwrap();
    assert_eq!(meta["status"], "complete");
    assert_eq!(meta["sessions"].as_array().unwrap().len(), 2);
    assert_eq!(meta["sessions"][1]["cells_run"], 11);

    // Resuming a finished sweep runs nothing and succeeds.
    let o = run(&["sweep", "--resume", d, "--no-plots"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_one_row_per_trial(&dir, 2, TINY_CELLS);
}

/// A sweep that runs for a second or two: 1 + 3 × 2 + 2 × 2 × 17 = 75 cells of 2 trials.
const SLOW: &[&str] = &[
    "sweep",
    "--n",
    "300",
    "--steps",
    "50",
    "--trials",
    "2",
    "--warmup",
    "0",
    "--cores",
    "1..2",
    "--chunks",
    "paper",
    "--no-plots",
];
const SLOW_CELLS: usize = 75;

/// Starts a sweep big enough to still be running when the first cells are written, and
/// returns it once `summary.csv` holds `cells` rows (or it has ended).
fn spawn_until_cells(dir: &Path, cells: usize) -> std::process::Child {
    let mut child = start(
        bench_sph()
            .args(SLOW)
            .args(["--out", dir.to_str().unwrap()]),
        Stdio::null(),
    );
    let summary = dir.join("summary.csv");
    poll_until(Duration::from_secs(120), Duration::from_millis(5), || {
        let written =
            std::fs::read_to_string(&summary).map_or(0, |t| t.lines().count().saturating_sub(1));
        written >= cells || child.try_wait().unwrap().is_some()
    });
    child
}

#[test]
fn a_sweep_killed_outright_resumes_without_duplicating_rows() {
    let (_tmp, dir) = scratch("r");
    let mut child = spawn_until_cells(&dir, 2);
    let was_running = child.try_wait().unwrap().is_none();
    let _ = child.kill(); // SIGKILL: no chance to tidy up
    child.wait().unwrap();
    if was_running {
        let kept = rows(&dir.join("summary.csv")).len();
        assert!(
            (2..SLOW_CELLS).contains(&kept),
            "{kept} cells before the kill"
        );
        eprintln!("killed after {kept} cells");
    }
    let d = dir.to_str().unwrap();
    let o = run(&["sweep", "--resume", d, "--no-plots"]);
    assert!(o.status.success(), "{}\n{}", stdout(&o), stderr(&o));
    assert_one_row_per_trial(&dir, 2, SLOW_CELLS);
}

#[test]
fn ctrl_c_keeps_the_finished_cells_and_exits_with_an_error_naming_resume() {
    let (_tmp, dir) = scratch("r");
    let mut child = spawn_until_cells(&dir, 1);
    let still_running = child.try_wait().unwrap().is_none();
    let sent = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .is_ok_and(|s| s.success());
    let out = child.wait_with_output().unwrap();
    if still_running && sent {
        assert!(!out.status.success());
        common::assert_interrupted(&dir, &common::text(&out.stderr));
    }
    let cells = rows(&dir.join("summary.csv")).len();
    assert_one_row_per_trial(&dir, 2, cells);
}

#[test]
fn an_existing_results_directory_is_refused_without_resume_or_force() {
    let (tmp, dir) = scratch("r");
    tiny_sweep(&dir, &[]);
    let d = dir.to_str().unwrap();
    let mut args = TINY.to_vec();
    args.extend(["--out", d]);
    fails_with(
        &args,
        &[
            "Error:",
            "already holds a sweep's results",
            "--resume",
            "--force",
        ],
    );
    assert_one_row_per_trial(&dir, 2, TINY_CELLS);

    // --force replaces the results; other files stay.
    std::fs::write(dir.join("notes.txt"), "mine").unwrap();
    tiny_sweep(&dir, &["--force", "--strategies", "seq"]);
    assert_one_row_per_trial(&dir, 2, 1);
    assert_file_holds(&dir.join("notes.txt"), "mine");

    // An existing empty directory is fine.
    let empty = tmp.path().join("empty");
    std::fs::create_dir(&empty).unwrap();
    tiny_sweep(&empty, &["--strategies", "seq"]);
}

#[test]
fn bad_ranges_give_a_clear_error_and_a_non_zero_exit() {
    let (_tmp, out) = scratch("never");
    let o = out.to_str().unwrap();
    for (option, value, needle) in [
        ("--cores", "5..1", "reversed"),
        ("--cores", "1..5:0", "step 0"),
        ("--cores", "0..2", "at least 1"),
        ("--cores", "abc", "not a whole number"),
        ("--cores", "", "no value given"),
        ("--chunks", "0", "at least 1"),
        ("--chunks", "10..2", "reversed"),
        ("--n", "1000..2000", "needs a step"),
    ] {
        fails_with(
            &["sweep", option, value, "--out", o],
            &["Error:", option, needle],
        );
    }
    assert!(!out.exists(), "nothing is written for bad input");
}

#[test]
fn an_unwritable_out_directory_is_an_error_before_anything_runs() {
    let (_tmp, file) = scratch("plain-file");
    std::fs::write(&file, "x").unwrap();
    let under_file = file.join("results");
    let mut args = TINY.to_vec();
    args.extend(["--out", under_file.to_str().unwrap()]);
    let o = fails_with(&args, &["Error:", "cannot create results directory"]);
    assert!(!stdout(&o).contains("[1/"), "no cell ran:\n{}", stdout(&o));
    let mut args = TINY.to_vec();
    args.extend(["--out", file.to_str().unwrap()]);
    fails_with(&args, &["Error:", "not a directory"]);
}

#[test]
fn resume_needs_a_sweep_directory_and_takes_no_new_parameters() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path().to_str().unwrap();
    fails_with(
        &["sweep", "--resume", d],
        &["Error:", "no sweep's meta.json"],
    );
    fails_with(&["sweep", "--resume", d, "--cores", "2"], &["--cores"]);
}

#[test]
fn cells_with_more_cores_than_hardware_threads_are_marked_and_warned_about() {
    let hw = std::thread::available_parallelism().map_or(1, |n| n.get());
    let (_tmp, dir) = scratch("r");
    let cores = format!("{hw}..{}", hw + 1);
    let o = sweep_into(
        &dir,
        &format!(
            "--n 40 --steps 2 --trials 1 --warmup 0 --strategies rayon-iter --cores {cores} \
             --no-plots"
        ),
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains("oversubscribed"), "{}", stderr(&o));
    assert!(stdout(&o).contains("(oversubscribed)"), "{}", stdout(&o));
    for r in rows(&dir.join("summary.csv")) {
        let over = num(&r, "cores") as usize > hw;
        assert_eq!(r["oversubscribed"], over.to_string(), "{r:?}");
        // One trial: no standard deviation.
        assert!(r["stddev_s"].is_empty());
    }
}

#[test]
fn a_resumed_sweep_runs_its_recorded_simd_path_and_refuses_another() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("s");
    let d = dir.to_str().unwrap();
    let mut args = vec!["--simd", "portable"];
    args.extend(TINY);
    args.extend([
        "--out",
        d,
        "--stop-after-cells",
        "2",
        "--fake-timings",
        "1,2",
    ]);
    fails_with(&args, &["Error:", "interrupted", "--resume"]);
    let meta = std::fs::read_to_string(dir.join("meta.json")).unwrap();
    assert!(meta.contains("\"simd\": \"portable\""), "{meta}");
    let widest = bench_sph::simd::SimdPath::widest();
    if widest != bench_sph::simd::SimdPath::Portable {
        let asked = widest.as_str();
        fails_with(
            &["--simd", asked, "sweep", "--resume", d, "--no-plots"],
            &[&format!(
                "--simd {asked}: this sweep was measured on portable"
            )],
        );
    }
    let o = run(&["sweep", "--resume", d, "--no-plots"]);
    assert!(o.status.success(), "{}\n{}", stdout(&o), stderr(&o));
}
