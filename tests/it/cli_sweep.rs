//! `bench-sph sweep` driven through the built binary: the files and their columns, statistics
//! that agree exactly with the trial rows (under the hidden test-only `--fake-timings`),
//! interruption and `--resume`, and a clear `Error: ...` with a non-zero exit for bad input.
//! No test asserts a duration.

use std::collections::BTreeMap;
use std::path::Path;
use std::process::{Command, Output, Stdio};
use std::time::Duration;

use crate::common;
use crate::common::{
    Row, assert_file_holds, assert_holds_all, bench_sph, fails_with, num, poll_until, read_json,
    rows, run, scratch, start, stderr, stdout, sweep_into, wait_until,
};

const TRIAL_HEADER: &str = "strategy,neighbors,preset,n,steps,cores,chunks,particles_per_chunk,\
    trial,wall_s,cpu_s,checksum,status,reason,foreign_cpu_s,steal_s,load1,pin,phase,round,\
    position,window_foreign_threads,contended";
const SUMMARY_HEADER: &str = "strategy,neighbors,preset,n,steps,cores,chunks,particles_per_chunk,\
    trials,mean_s,stddev_s,min_s,median_s,max_s,cpu_mean_s,speedup,efficiency,outliers,\
    oversubscribed,checksum,status,reason,mean_ci_low_s,mean_ci_high_s,speedup_ci_low,\
    speedup_ci_high,foreign_cpu_mean_s,contended,reference_shard,pin,smt,phase";

/// The strategies of the tiny and slow sweeps: three that ignore `--chunks`, two that use it
/// (fixed, so that the cell counts do not grow with the registry).
const SIX: &str = "seq,rayon-iter,rayon-spawn,rayon-chunks,crossbeam-pool,std-static";

/// A tiny sweep: 1 seq cell + 3 strategies × 2 cores + 2 strategies × 2 cores × 2 chunks = 15
/// cells, 2 rounds, no confirmation (tests that want one ask for it).
const TINY: &[&str] = &[
    "sweep",
    "--strategies",
    SIX,
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
    "--confirm-rounds",
    "0",
    "--no-plots",
];
const TINY_CELLS: usize = 15;

/// The tiny sweep's arguments with `extra`: an option the tiny sweep already gives takes the
/// value `extra` gives it; the rest is added.
fn tiny_args<'a>(extra: &[&'a str]) -> Vec<&'a str> {
    let mut args = TINY.to_vec();
    let mut rest = extra.iter();
    while let Some(&item) = rest.next() {
        match args.iter().position(|a| *a == item) {
            Some(at) if item.starts_with("--") && at + 1 < args.len() => {
                args[at + 1] = rest.next().expect("a value");
            }
            _ => args.push(item),
        }
    }
    args
}

/// Runs the tiny sweep (with `extra`, see [`tiny_args`]) into `dir` and expects success.
fn tiny_sweep(dir: &Path, extra: &[&str]) -> Output {
    let mut args = tiny_args(extra);
    args.extend(["--out", dir.to_str().unwrap()]);
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

/// The columns that name a cell and its phase.
fn cell_key(row: &Row) -> String {
    [
        "strategy",
        "neighbors",
        "preset",
        "n",
        "steps",
        "cores",
        "chunks",
        "phase",
    ]
    .map(|c| row[c].as_str())
    .join("|")
}

/// The rows of `phase`.
fn of_phase<'a>(rows: &'a [Row], phase: &str) -> Vec<&'a Row> {
    rows.iter().filter(|r| r["phase"] == phase).collect()
}

/// Every cell's trial rows, by cell key.
fn trials_by_cell(trials: &[Row]) -> BTreeMap<String, Vec<&Row>> {
    let mut by_cell: BTreeMap<String, Vec<&Row>> = BTreeMap::new();
    for t in trials {
        by_cell.entry(cell_key(t)).or_default().push(t);
    }
    by_cell
}

/// Asserts one row per round, numbered 1..=rounds (trial and round alike), for every grid
/// summary row, and no other rows (the sweep ran without confirmation).
fn assert_one_row_per_trial(dir: &Path, trials_per_cell: usize, cells: usize) {
    let summary = rows(&dir.join("summary.csv"));
    let trials = rows(&dir.join("trials.csv"));
    assert!(summary.iter().chain(&trials).all(|r| r["phase"] == "grid"));
    assert_eq!(summary.len(), cells, "summary rows");
    let by_cell = trials_by_cell(&trials);
    assert_eq!(by_cell.len(), cells, "cells in trials.csv");
    let mut keys: Vec<String> = summary.iter().map(cell_key).collect();
    keys.sort();
    keys.dedup();
    assert_eq!(keys.len(), cells, "duplicate summary rows");
    for (key, rows) in &by_cell {
        let mut numbers: Vec<(&str, &str)> = rows
            .iter()
            .map(|r| (r["trial"].as_str(), r["round"].as_str()))
            .collect();
        numbers.sort_by_key(|&(t, _)| t.parse::<usize>().unwrap());
        let want: Vec<String> = (1..=trials_per_cell).map(|k| k.to_string()).collect();
        let want: Vec<(&str, &str)> = want.iter().map(|k| (k.as_str(), k.as_str())).collect();
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

    let meta = read_json(&dir.join("meta.json"));
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
    assert_eq!(meta["params"]["schedule"], "rounds");
    assert_eq!(meta["params"]["confirm_rounds"], 0);
    assert_eq!(meta["statistics"]["intervals"], "student-t");
    assert_eq!(meta["statistics"]["shuffle_seed"], 2019);
    assert_eq!(meta["statistics"]["contention_window_s"], 1.0);
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
            "15 cells × 2 rounds",
            "shuffled from --seed 2019",
            "estimated time",
            "Fastest cell per strategy",
            "trials.csv",
            "summary.csv",
            "meta.json",
        ],
    );
}

/// The geometric mean of `xs` and its Student-t interval for three values (t = 4.3027 at two
/// degrees of freedom), computed here independently of the crate.
fn geometric_three(xs: &[f64]) -> (f64, f64, f64) {
    assert_eq!(xs.len(), 3);
    let logs: Vec<f64> = xs.iter().map(|x| x.ln()).collect();
    let m = mean(&logs);
    let sd = (logs.iter().map(|l| (l - m) * (l - m)).sum::<f64>() / 2.0).sqrt();
    let half = 4.302_652_729_749_464 * sd / 3f64.sqrt();
    (m.exp(), (m - half).exp(), (m + half).exp())
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-12 * a.abs().max(b.abs())
}

#[test]
fn summary_statistics_agree_exactly_with_the_trial_rows_under_fake_timings() {
    let (_tmp, dir) = scratch("r");
    // Seven items for three rounds a cell: each cell gets a different slice of the list.
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

    // The seq cell got 1, 2, 3 (CPU 0.5, 1, 1.5) in rounds 1, 2, 3; the next cell 2, 2, 9.
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
        ("speedup_ci_low", 1.0),
        ("speedup_ci_high", 1.0),
    ] {
        assert_eq!(num(seq, column), want, "seq {column}");
    }
    let second = &summary[1];
    assert_eq!(num(second, "mean_s"), 13.0 / 3.0);
    assert_eq!(num(second, "median_s"), 2.0);
    assert_eq!(num(second, "outliers"), 1.0, "9 is beyond 3 MAD (MAD = 0)");
    // Paired by round: 1/2, 2/2, 3/9.
    let (g, _, _) = geometric_three(&[0.5, 1.0, 3.0 / 9.0]);
    assert!(close(num(second, "speedup"), g), "{second:?}");

    let seq_by_round: BTreeMap<String, f64> = by_cell[&cell_key(seq)]
        .iter()
        .map(|r| (r["round"].clone(), num(r, "wall_s")))
        .collect();
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
        let ratios: Vec<f64> = rows
            .iter()
            .map(|r| seq_by_round[&r["round"]] / num(r, "wall_s"))
            .collect();
        let (speedup, low, high) = geometric_three(&ratios);
        let (_, mean_low, mean_high) = geometric_three(&walls);
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
        for (column, want) in [
            ("speedup", speedup),
            ("speedup_ci_low", low),
            ("speedup_ci_high", high),
            ("mean_ci_low_s", mean_low),
            ("mean_ci_high_s", mean_high),
            ("efficiency", speedup / cores),
        ] {
            assert!(close(num(s, column), want), "{column} {want} in {s:?}");
        }
    }
    let meta = std::fs::read_to_string(dir.join("meta.json")).unwrap();
    assert!(meta.contains(fake), "fake timings are recorded: {meta}");
}

/// The runs of `trials` in file order, grouped by round: each round's cell keys in the order
/// they ran.
fn rounds_in_order(trials: &[Row]) -> Vec<Vec<String>> {
    let mut rounds: Vec<Vec<String>> = Vec::new();
    let mut last = String::new();
    for t in trials {
        if t["round"] != last {
            last = t["round"].clone();
            rounds.push(Vec::new());
        }
        let position: usize = t["position"].parse().unwrap();
        let round = rounds.last_mut().unwrap();
        assert_eq!(
            position,
            round.len() + 1,
            "positions count up within a round"
        );
        round.push(cell_key(t));
    }
    rounds
}

#[test]
fn rounds_run_every_cell_once_in_an_order_shuffled_from_the_seed() {
    let tmp = tempfile::tempdir().unwrap();
    let sweep = |name: &str, extra: &[&str]| {
        let dir = tmp.path().join(name);
        let mut args = vec!["--trials", "4", "--fake-timings", "1,2,3"];
        args.extend(extra);
        tiny_sweep(&dir, &args);
        rows(&dir.join("trials.csv"))
    };
    let trials = sweep("a", &[]);
    let rounds = rounds_in_order(&trials);
    assert_eq!(rounds.len(), 4, "rounds one after the other");
    let mut first_round = rounds[0].clone();
    first_round.sort();
    for (i, round) in rounds.iter().enumerate() {
        let mut cells = round.clone();
        cells.sort();
        assert_eq!(cells, first_round, "round {} runs every cell once", i + 1);
    }
    assert_eq!(first_round.len(), TINY_CELLS);
    assert!(
        rounds.windows(2).any(|w| w[0] != w[1]),
        "each round its own order"
    );
    assert!(
        rounds.iter().any(|r| !r[0].starts_with("seq|")),
        "seq is not always first"
    );
    // The same seed, the same order; another seed, another.
    assert_eq!(rounds_in_order(&sweep("b", &[])), rounds);
    assert_ne!(rounds_in_order(&sweep("c", &["--seed", "7"])), rounds);
    // --schedule cells: each cell's runs back to back, seq first, in plan order.
    let cells = sweep("d", &["--schedule", "cells"]);
    let keys: Vec<String> = cells.iter().map(cell_key).collect();
    assert!(keys[..4].iter().all(|k| k.starts_with("seq|")));
    assert!(keys.chunks(4).all(|c| c.iter().all(|k| *k == c[0])));
}

#[test]
fn the_confirmation_rounds_measure_each_strategys_best_cells_again() {
    let (_tmp, dir) = scratch("r");
    // The runs take the times in turn: every grid cell of rayon-chunks and crossbeam-pool
    // gets its own mean, so each has a best and a runner-up per cores, and no strategy is
    // twice as slow as another (out of the running).
    tiny_sweep(
        &dir,
        &[
            "--confirm-rounds",
            "3",
            "--fake-timings",
            "1.5,1.4,1.3,1.2,1.1,1.6,1.7",
        ],
    );
    let summary = rows(&dir.join("summary.csv"));
    let trials = rows(&dir.join("trials.csv"));
    let grid = of_phase(&summary, "grid");
    let confirmed = of_phase(&summary, "confirm");
    assert_eq!(grid.len(), TINY_CELLS);
    // seq, rayon-iter, rayon-spawn, std-static at 1 and 2 cores (6 cells), and best and
    // runner-up of rayon-chunks and crossbeam-pool at 1 and 2 cores (8).
    assert_eq!(confirmed.len(), 1 + 6 + 8, "{confirmed:?}");
    assert_eq!(confirmed[0]["strategy"], "seq");
    for c in &confirmed {
        assert_eq!(c["trials"], "3", "{c:?}");
        let runs: Vec<&Row> = of_phase(&trials, "confirm")
            .into_iter()
            .filter(|t| cell_key(t) == cell_key(c))
            .collect();
        assert_eq!(runs.len(), 3, "{c:?}");
    }
    // The confirmation's runs come after every grid run.
    let last_grid = trials.iter().rposition(|t| t["phase"] == "grid").unwrap();
    let first_confirm = trials.iter().position(|t| t["phase"] == "confirm").unwrap();
    assert!(last_grid < first_confirm);
}

#[test]
fn a_sweep_stopped_midway_and_resumed_ends_with_exactly_one_row_per_run() {
    let tmp = tempfile::tempdir().unwrap();
    let fake = ["--fake-timings", "1,2,3,4,5", "--trials", "3"];
    // The same sweep without interruption, to compare with.
    let whole = tmp.path().join("whole");
    tiny_sweep(&whole, &fake);

    let dir = tmp.path().join("r");
    let d = dir.to_str().unwrap();
    let mut args = tiny_args(&fake);
    // 20 runs: round 1 (15 runs) and a third of round 2.
    args.extend(["--out", d, "--stop-after-runs", "20"]);
    fails_with(&args, &["Error:", "interrupted", "--resume"]);
    let kept = rows(&dir.join("trials.csv"));
    assert_eq!(kept.len(), 20);
    assert!(rows(&dir.join("summary.csv")).is_empty());
    let meta = std::fs::read_to_string(dir.join("meta.json")).unwrap();
    assert!(meta.contains("\"status\": \"interrupted\""), "{meta}");

    // A kill in the middle of writing the next run: a line cut off.
    let trials_path = dir.join("trials.csv");
    let mut text = std::fs::read_to_string(&trials_path).unwrap();
    text.push_str("rayon-spawn,all-pairs,seed,60,3,2,,,2,0.0");
    std::fs::write(&trials_path, text).unwrap();

    let o = run(&["sweep", "--resume", d, "--no-plots"]);
    assert!(o.status.success(), "{}\n{}", stdout(&o), stderr(&o));
    assert!(
        stdout(&o).contains("20 runs of unfinished rounds kept"),
        "{}",
        stdout(&o)
    );
    assert_one_row_per_trial(&dir, 3, TINY_CELLS);
    // Same parameters, same fake times, the same order: the same files as the uninterrupted
    // sweep.
    for file in ["trials.csv", "summary.csv"] {
        assert_eq!(
            std::fs::read_to_string(dir.join(file)).unwrap(),
            std::fs::read_to_string(whole.join(file)).unwrap(),
            "{file}"
        );
    }
    let meta = read_json(&dir.join("meta.json"));
    assert_eq!(meta["status"], "complete");
    assert_eq!(meta["sessions"].as_array().unwrap().len(), 2);
    assert_eq!(meta["sessions"][1]["cells_run"], TINY_CELLS);

    // Resuming a finished sweep runs nothing and succeeds.
    let o = run(&["sweep", "--resume", d, "--no-plots"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_one_row_per_trial(&dir, 3, TINY_CELLS);
}

#[test]
fn every_cell_is_flagged_beside_a_busy_machine_and_none_on_a_quiet_one() {
    let tmp = tempfile::tempdir().unwrap();
    for (share, contended) in [("0.5", "true"), ("0", "false")] {
        let dir = tmp.path().join(share);
        // Short runs (5 ms): judged over windows, not alone.
        let o = tiny_sweep(
            &dir,
            &["--fake-timings", "0.005", "--fake-contention", share],
        );
        let summary = rows(&dir.join("summary.csv"));
        assert!(
            summary.iter().all(|r| r["contended"] == contended),
            "share {share}: {summary:?}"
        );
        let trials = rows(&dir.join("trials.csv"));
        assert!(trials.iter().all(|t| t["contended"] == contended));
        let lines = stdout(&o)
            .lines()
            .filter(|l| l.starts_with('[') && l.ends_with("  contended"))
            .count();
        assert_eq!(lines, if contended == "true" { TINY_CELLS } else { 0 });
        let warned = stderr(&o).contains("--remeasure-contended");
        assert_eq!(warned, contended == "true", "{}", stderr(&o));
    }
}

#[test]
fn a_busy_machine_can_be_waited_for_and_its_contended_groups_measured_again() {
    let (_tmp, dir) = scratch("r");
    let d = dir.to_str().unwrap();
    let o = tiny_sweep(
        &dir,
        &[
            "--strategies",
            "rayon-iter",
            "--fake-timings",
            "0.01",
            "--fake-contention",
            "0.9",
            "--wait-quiet",
            "1",
        ],
    );
    assert_holds_all(
        "stderr",
        &stderr(&o),
        &[
            "waiting up to 1.0 s for a quiet machine",
            "still busy after",
        ],
    );
    let first: Vec<String> = rows(&dir.join("trials.csv"))
        .iter()
        .map(|t| t["contended"].clone())
        .collect();
    assert!(first.iter().all(|c| c == "true"));
    let o = run(&[
        "sweep",
        "--resume",
        d,
        "--remeasure-contended",
        "--no-plots",
    ]);
    assert!(o.status.success(), "{}\n{}", stdout(&o), stderr(&o));
    assert!(
        stdout(&o).contains("1 group with contended cells will be measured again"),
        "{}",
        stdout(&o)
    );
    assert_one_row_per_trial(&dir, 2, 3);
    let meta = read_json(&dir.join("meta.json"));
    assert_eq!(meta["sessions"][1]["cells_run"], 3);
    // --remeasure-contended belongs to --resume.
    fails_with(
        &["sweep", "--remeasure-contended", "--out", d],
        &["--resume"],
    );
}

#[test]
fn a_shard_runs_its_own_rounds_with_its_own_seq_and_no_confirmation() {
    let tmp = tempfile::tempdir().unwrap();
    let mut seen = Vec::new();
    for i in 1..=2 {
        let dir = tmp.path().join(format!("s{i}"));
        let shard = format!("{i}/2");
        tiny_sweep(&dir, &["--shard", &shard, "--fake-timings", "1,2"]);
        let trials = rows(&dir.join("trials.csv"));
        let rounds = rounds_in_order(&trials);
        assert_eq!(rounds.len(), 2);
        assert!(
            rounds
                .iter()
                .all(|r| r.iter().filter(|k| k.starts_with("seq|")).count() == 1)
        );
        assert!(trials.iter().all(|t| t["phase"] == "grid"));
        seen.extend(rounds[0].iter().filter(|k| !k.starts_with("seq|")).cloned());
    }
    seen.sort();
    seen.dedup();
    assert_eq!(seen.len(), TINY_CELLS - 1, "the shards share the cells out");
    let (_t, dir) = scratch("never");
    let mut args = TINY.to_vec();
    let at = args.iter().position(|a| *a == "--confirm-rounds").unwrap();
    args[at + 1] = "2";
    args.extend(["--shard", "1/2", "--out", dir.to_str().unwrap()]);
    fails_with(&args, &["Error:", "--confirm-rounds 2 with --shard 1/2"]);
}

/// A sweep that runs for two seconds or so: 1 + 3 × 2 + 2 × 2 × 2 = 15 cells of 2 rounds, no
/// confirmation, each run about 50 ms of steps besides its threads' start and wake, so that a
/// signal sent once the first runs are written finds it running with seconds to spare (with
/// 200 steps a run, about a tenth of that, SIGINT once came after the last run).
const SLOW: &[&str] = &[
    "sweep",
    "--strategies",
    SIX,
    "--n",
    "300",
    "--steps",
    "2000",
    "--trials",
    "2",
    "--warmup",
    "0",
    "--cores",
    "1..2",
    "--chunks",
    "2,7",
    "--confirm-rounds",
    "0",
    "--no-plots",
];
const SLOW_CELLS: usize = 15;

/// Starts a sweep big enough to still be running when the first runs are written, and
/// returns it once `trials.csv` holds `runs` rows (or it has ended).
fn spawn_until_runs(dir: &Path, runs: usize) -> std::process::Child {
    let mut child = start(
        bench_sph()
            .args(SLOW)
            .args(["--out", dir.to_str().unwrap()]),
        Stdio::null(),
    );
    let trials = dir.join("trials.csv");
    poll_until(Duration::from_secs(120), Duration::from_millis(5), || {
        let written =
            std::fs::read_to_string(&trials).map_or(0, |t| t.lines().count().saturating_sub(1));
        written >= runs || child.try_wait().unwrap().is_some()
    });
    child
}

#[test]
fn a_sweep_killed_outright_resumes_without_duplicating_rows() {
    let (_tmp, dir) = scratch("r");
    let mut child = spawn_until_runs(&dir, 2);
    let was_running = child.try_wait().unwrap().is_none();
    let _ = child.kill(); // SIGKILL: no chance to tidy up
    child.wait().unwrap();
    if was_running {
        let kept = rows(&dir.join("trials.csv")).len();
        assert!(
            (2..2 * SLOW_CELLS).contains(&kept),
            "{kept} runs before the kill"
        );
        eprintln!("killed after {kept} runs");
    } else {
        eprintln!("the sweep ended before the kill: only the resume was checked");
    }
    let d = dir.to_str().unwrap();
    let o = run(&["sweep", "--resume", d, "--no-plots"]);
    assert!(o.status.success(), "{}\n{}", stdout(&o), stderr(&o));
    assert_one_row_per_trial(&dir, 2, SLOW_CELLS);
}

/// Sends `signal` (a name `kill` takes) to a running sweep and checks that it stops as
/// interrupted, keeping every run measured, and that `--resume` finishes it. Where this test
/// runs under `nohup`, the sweep inherits an ignored SIGHUP and must finish as if none came.
fn a_signal_keeps_the_runs_measured_and_resume_finishes(signal: &str) {
    let (_tmp, dir) = scratch("r");
    let mut child = spawn_until_runs(&dir, 1);
    let still_running = child.try_wait().unwrap().is_none();
    let sent = Command::new("kill")
        .args([&format!("-{signal}"), &child.id().to_string()])
        .status()
        .is_ok_and(|s| s.success());
    let out = child.wait_with_output().unwrap();
    let ignored = signal == "HUP" && sph_harness::signals::sighup_ignored_at_start();
    if ignored {
        eprintln!("SIGHUP is ignored here (nohup): the sweep must not have stopped");
        assert!(out.status.success(), "{}", common::text(&out.stderr));
        assert_one_row_per_trial(&dir, 2, SLOW_CELLS);
    } else if still_running && sent {
        assert!(!out.status.success());
        common::assert_interrupted(&dir, &common::text(&out.stderr));
    } else {
        eprintln!("SIG{signal} not delivered to a running sweep: only the resume was checked");
    }
    // Every run written once, in whole rounds and the start of the next.
    let trials = rows(&dir.join("trials.csv"));
    let by_cell = trials_by_cell(&trials);
    assert!(by_cell.values().all(|runs| runs.len() <= 2));
    let d = dir.to_str().unwrap();
    let o = run(&["sweep", "--resume", d, "--no-plots"]);
    assert!(o.status.success(), "{}\n{}", stdout(&o), stderr(&o));
    assert_one_row_per_trial(&dir, 2, SLOW_CELLS);
}

#[test]
fn ctrl_c_keeps_the_runs_measured_and_exits_with_an_error_naming_resume() {
    a_signal_keeps_the_runs_measured_and_resume_finishes("INT");
}

#[test]
fn sigterm_ends_a_sweep_as_ctrl_c_does_marked_interrupted() {
    a_signal_keeps_the_runs_measured_and_resume_finishes("TERM");
}

#[test]
fn sighup_ends_a_sweep_as_ctrl_c_does_marked_interrupted() {
    a_signal_keeps_the_runs_measured_and_resume_finishes("HUP");
}

#[test]
fn under_nohup_a_closed_terminal_does_not_stop_a_sweep() {
    let (_tmp, dir) = scratch("r");
    // `trap '' HUP` ignores SIGHUP as nohup does, and `exec` keeps that for the sweep.
    let bin = env!("CARGO_BIN_EXE_bench-sph");
    let mut child = start(
        Command::new("sh")
            .args(["-c", "trap '' HUP; exec \"$0\" \"$@\""])
            .arg(bin)
            .args(SLOW)
            .args(["--out", dir.to_str().unwrap()]),
        Stdio::null(),
    );
    let trials = dir.join("trials.csv");
    wait_until("the sweep never wrote a run", || {
        trials.exists() || child.try_wait().unwrap().is_some()
    });
    let _ = Command::new("kill")
        .args(["-HUP", &child.id().to_string()])
        .status();
    let out = child.wait_with_output().unwrap();
    assert!(out.status.success(), "{}", common::text(&out.stderr));
    let meta = std::fs::read_to_string(dir.join("meta.json")).unwrap();
    assert!(meta.contains("\"status\": \"complete\""), "{meta}");
    assert_one_row_per_trial(&dir, 2, SLOW_CELLS);
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
    assert!(stdout(&o).contains("  oversubscribed"), "{}", stdout(&o));
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
        "--stop-after-runs",
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
