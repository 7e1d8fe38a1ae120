//! `bench-sph trace` driven through the built binary: for every strategy, trace.json holds
//! exactly one complete event per kernel call, covering every particle of every pass of every
//! step once, on at most `cores` workers whose events never overlap; timeline.png and
//! stats.csv are there and well formed; the output directory is claimed (foreign files are
//! refused, never replaced) and every file is written whole; an oversized trace is refused
//! before it runs; `report` embeds only valid trace directories; bad input is one
//! `Error: ...` line and a non-zero exit. No test asserts a duration.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Output;

use serde_json::Value;
use sph_strategies::StrategyName;

use crate::common::{
    DIVERGING_INIT, assert_file_holds, fails_with, line_containing, names, read_json, run, scratch,
    stderr, stdout,
};

const N: usize = 200;
const STEPS: usize = 2;
const CORES: usize = 2;
const CHUNKS: usize = 7;
const PASSES: [&str; 2] = ["density", "forces"];
const STATS_HEADER: &str = "kind,name,threads,kernel_calls,busy_ms,span_ms,idle_pct,imbalance";

fn trace(strategy: StrategyName, out: &Path, extra: &[&str]) -> Output {
    let (n, steps, cores, chunks) = (
        N.to_string(),
        STEPS.to_string(),
        CORES.to_string(),
        CHUNKS.to_string(),
    );
    let mut args = vec![
        "trace",
        "--strategy",
        strategy.as_str(),
        "--n",
        &n,
        "--steps",
        &steps,
        "--cores",
        &cores,
        "--chunks",
        &chunks,
        "--out",
        out.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    run(&args)
}

/// Kernel calls per pass, where the strategy fixes it (rayon-iter lets rayon decide).
fn expected_calls(strategy: StrategyName) -> Option<usize> {
    let config = sph_strategies::Config::new(CORES, CHUNKS);
    strategy.info().kernel_calls(N, &config)
}

fn workers(strategy: StrategyName) -> usize {
    strategy.info().effective_cores(CORES)
}

/// A complete kernel event: (step, pass, worker, tid, first, len, ts, dur).
#[derive(Debug, Clone)]
struct Kernel {
    step: u64,
    pass: String,
    worker: u64,
    tid: u64,
    first: usize,
    len: usize,
    ts: f64,
    dur: f64,
}

/// The complete events of the worker tracks whose category is one of `cats` (`pass` for the
/// model's passes, `rebuild` for the grid rebuild's kernel calls).
fn kernels(json: &Value, cats: &[&str]) -> Vec<Kernel> {
    json["traceEvents"]
        .as_array()
        .expect("traceEvents is an array")
        .iter()
        .filter(|e| cats.iter().any(|c| e["cat"] == *c))
        .map(|e| {
            assert_eq!(e["ph"], "X", "{e}");
            let args = &e["args"];
            Kernel {
                step: args["step"].as_u64().unwrap(),
                pass: e["name"].as_str().unwrap().to_owned(),
                worker: args["worker"].as_u64().unwrap(),
                tid: e["tid"].as_u64().unwrap(),
                first: args["first"].as_u64().unwrap() as usize,
                len: args["len"].as_u64().unwrap() as usize,
                ts: e["ts"].as_f64().unwrap(),
                dur: e["dur"].as_f64().unwrap(),
            }
        })
        .collect()
}

/// Checks trace.json in `dir`; returns the number of kernel calls (passes and rebuilds).
fn check_trace_json(strategy: StrategyName, dir: &Path) -> usize {
    let text = std::fs::read_to_string(dir.join("trace.json")).unwrap();
    let json: Value = serde_json::from_str(&text).expect("trace.json is valid JSON");
    let events = kernels(&json, &["pass"]);

    let mut by_pass: BTreeMap<(u64, String), Vec<&Kernel>> = BTreeMap::new();
    for e in &events {
        by_pass.entry((e.step, e.pass.clone())).or_default().push(e);
    }
    let expected_keys: Vec<(u64, String)> = (1..=STEPS as u64)
        .flat_map(|s| PASSES.map(|p| (s, p.to_owned())))
        .collect();
    assert_eq!(
        by_pass.keys().cloned().collect::<Vec<_>>(),
        expected_keys,
        "{strategy}: every pass of every step"
    );
    for ((step, pass), mut calls) in by_pass {
        if let Some(expected) = expected_calls(strategy) {
            assert_eq!(calls.len(), expected, "{strategy}: step {step} {pass}");
        }
        calls.sort_by_key(|e| e.first);
        let mut next = 0;
        for e in calls {
            assert_eq!(
                e.first, next,
                "{strategy}: step {step} {pass}: gap or overlap"
            );
            assert!(e.len > 0);
            next += e.len;
        }
        assert_eq!(
            next, N,
            "{strategy}: step {step} {pass} covers every particle"
        );
    }

    let all = kernels(&json, &["pass", "rebuild"]);
    let mut per_worker: BTreeMap<u64, Vec<&Kernel>> = BTreeMap::new();
    for e in &all {
        assert!(
            (e.worker as usize) < workers(strategy),
            "{strategy}: worker {}",
            e.worker
        );
        assert_eq!(e.tid, e.worker, "{strategy}: one track per worker");
        assert!(e.dur >= 0.0);
        per_worker.entry(e.worker).or_default().push(e);
    }
    for (worker, mut list) in per_worker {
        list.sort_by(|a, b| a.ts.total_cmp(&b.ts));
        for pair in list.windows(2) {
            // 1 ns of slack for the microsecond conversion's rounding.
            assert!(
                pair[0].ts + pair[0].dur <= pair[1].ts + 1e-3,
                "{strategy}: worker {worker}: {:?} overlaps {:?}",
                pair[0],
                pair[1]
            );
        }
    }

    let track_names: Vec<&str> = json["traceEvents"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|e| e["name"] == "thread_name")
        .map(|e| e["args"]["name"].as_str().unwrap())
        .collect();
    assert_eq!(track_names.len(), workers(strategy) + 1, "{track_names:?}");
    assert!(track_names[0].starts_with("worker 0"), "{track_names:?}");
    all.len()
}

fn check_timeline_png(strategy: StrategyName, dir: &Path) {
    let bytes = std::fs::read(dir.join("timeline.png")).unwrap();
    let decoder = png::Decoder::new(std::io::Cursor::new(bytes));
    let reader = decoder.read_info().expect("timeline.png decodes");
    let info = reader.info();
    let tracks = workers(strategy) as u32 + 1;
    assert_eq!(
        (info.width, info.height),
        (1600, 84 + 2 * (104 + 56 * tracks)),
        "{strategy}"
    );
}

fn check_stats_csv(strategy: StrategyName, dir: &Path, kernel_events: usize, grid: bool) {
    let text = std::fs::read_to_string(dir.join("stats.csv")).unwrap();
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some(STATS_HEADER));
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    let kinds: Vec<&str> = rows.iter().map(|r| r[0]).collect();
    let mut expected = vec!["worker"; workers(strategy)];
    expected.extend(vec!["pass"; PASSES.len() + usize::from(grid)]);
    expected.push("total");
    assert_eq!(kinds, expected, "{strategy}");
    assert!(rows.iter().all(|r| r.len() == 8));
    let total = rows.last().unwrap();
    assert_eq!(total[3].parse::<usize>().unwrap(), kernel_events);
    let worker_calls: usize = rows
        .iter()
        .filter(|r| r[0] == "worker")
        .map(|r| r[3].parse::<usize>().unwrap())
        .sum();
    assert_eq!(worker_calls, kernel_events);
}

#[test]
fn every_strategy_records_one_event_per_kernel_call_on_at_most_cores_workers_without_overlap() {
    let tmp = tempfile::tempdir().unwrap();
    for &strategy in StrategyName::ALL {
        let dir = tmp.path().join(strategy.as_str());
        let o = trace(strategy, &dir, &[]);
        assert!(o.status.success(), "{strategy}: {}", stderr(&o));
        let events = check_trace_json(strategy, &dir);
        check_timeline_png(strategy, &dir);
        check_stats_csv(strategy, &dir, events, false);
        let out = stdout(&o);
        assert!(
            out.contains(&format!("TASKS: {events} kernel calls")),
            "{out}"
        );
    }
}

#[test]
fn with_the_grid_the_rebuild_s_kernel_calls_are_traced_beside_the_passes() {
    let tmp = tempfile::tempdir().unwrap();
    for strategy in [StrategyName::RayonChunks, StrategyName::StdStatic] {
        let dir = tmp.path().join(strategy.as_str());
        let o = trace(strategy, &dir, &["--neighbors", "grid"]);
        assert!(o.status.success(), "{strategy}: {}", stderr(&o));
        let events = check_trace_json(strategy, &dir);
        check_stats_csv(strategy, &dir, events, true);
        let json = read_json(&dir.join("trace.json"));
        let rebuilds = kernels(&json, &["rebuild"]);
        assert!(!rebuilds.is_empty(), "{strategy}");
        assert!(rebuilds.iter().all(|e| e.pass == "grid rebuild"));
    }
}

#[test]
fn a_traced_run_ends_in_the_same_state_as_simulate() {
    let tmp = tempfile::tempdir().unwrap();
    let o = trace(StrategyName::RayonChunks, tmp.path(), &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    let meta = read_json(&tmp.path().join("meta.json"));
    let s = run(&[
        "simulate",
        "--n",
        "200",
        "--steps",
        "2",
        "--json",
        "--strategy",
        "seq",
    ]);
    assert!(s.status.success(), "{}", stderr(&s));
    let sim: Value = serde_json::from_str(stdout(&s).trim()).unwrap();
    assert_eq!(meta["checksum"], sim["checksum"]);
    assert_eq!(meta["strategy"], "rayon-chunks");
    assert_eq!(meta["chunks"], CHUNKS);
    assert_eq!(meta["n"], N);
}

#[test]
fn compare_times_untraced_and_traced_runs_and_prints_both() {
    let tmp = tempfile::tempdir().unwrap();
    let o = trace(StrategyName::CrossbeamPool, tmp.path(), &["--compare", "2"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let out = stdout(&o);
    assert!(out.contains("compare (2 runs each"), "{out}");
    assert!(
        out.contains("untraced min") && out.contains("traced min"),
        "{out}"
    );
    assert!(tmp.path().join("trace.json").is_file());
}

#[test]
fn the_timeline_can_show_only_the_last_steps() {
    let tmp = tempfile::tempdir().unwrap();
    let o = trace(StrategyName::Seq, tmp.path(), &["--timeline-steps", "1"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let meta = read_json(&tmp.path().join("meta.json"));
    assert_eq!(meta["timeline_steps"], serde_json::json!([2, 2]));
}

#[test]
fn an_unwritable_output_directory_is_an_error_before_anything_runs() {
    let (_tmp, file) = scratch("a-file");
    std::fs::write(&file, "x").unwrap();
    let out = file.join("sub");
    let o = run(&[
        "trace",
        "--strategy",
        "seq",
        "--n",
        "10",
        "--out",
        out.to_str().unwrap(),
    ]);
    let err = stderr(&o);
    assert!(!o.status.success());
    assert!(err.starts_with("Error: cannot create directory"), "{err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
}

/// Runs `trace` with `options` from a diverging init file (written into `dir`) into `out`.
fn trace_diverging(dir: &Path, out: &Path, options: &[&str]) -> Output {
    let init = dir.join("boom.csv");
    std::fs::write(&init, DIVERGING_INIT).unwrap();
    let files = [
        "--init",
        init.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ];
    run(&[&["trace"][..], options, &files].concat())
}

#[test]
fn a_diverging_run_is_an_error_and_leaves_no_trace_files() {
    let (tmp, out) = scratch("t");
    let options = ["--strategy", "rayon-chunks", "--cores", "2"];
    let o = trace_diverging(tmp.path(), &out, &options);
    let err = stderr(&o);
    assert!(!o.status.success());
    assert!(
        err.starts_with("Error: the simulation diverged at step 1"),
        "{err}"
    );
    assert!(names(&out).is_empty(), "{:?}", names(&out));
}

#[test]
fn bad_counts_and_names_are_rejected() {
    let base = ["trace", "--out", "unused-dir", "--strategy"];
    for (rest, needle) in [
        (&["turbo"][..], "unknown strategy 'turbo'"),
        (&["seq", "--steps", "0"], "between 1 and"),
        (&["seq", "--cores", "0"], "between 1 and"),
        (&["seq", "--compare", "x"], "whole number"),
        (
            &["seq", "--warmup", "1001"],
            "warm-ups must be between 0 and 1000, not 1001",
        ),
    ] {
        fails_with(&[&base[..], rest].concat(), &[needle]);
    }
    fails_with(&["trace", "--strategy", "seq"], &["--out"]);
    assert!(!Path::new("unused-dir").exists());
}

/// Runs and expects exactly one `Error: ...` line containing `needle` and a failure.
fn one_error_line(o: &Output, needle: &str) -> String {
    let err = stderr(o);
    assert!(!o.status.success(), "succeeded: {}", stdout(o));
    assert!(err.starts_with("Error: ") && err.contains(needle), "{err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    err
}

/// The bytes of every file in `dir`, by name.
fn contents(dir: &Path) -> BTreeMap<String, Vec<u8>> {
    names(dir)
        .into_iter()
        .map(|n| {
            let bytes = std::fs::read(dir.join(&n)).unwrap();
            (n, bytes)
        })
        .collect()
}

/// A finished sweep: the report fixture's meta.json, summary.csv and trials.csv.
fn finished_sweep(dir: &Path) {
    let fixture = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/report-results");
    std::fs::create_dir_all(dir).unwrap();
    for name in ["meta.json", "summary.csv", "trials.csv"] {
        std::fs::copy(fixture.join(name), dir.join(name)).unwrap();
    }
}

fn meta(dir: &Path) -> Value {
    read_json(&dir.join("meta.json"))
}

#[test]
fn trace_into_a_finished_sweep_directory_is_refused_and_the_sweep_is_untouched() {
    let (_tmp, sweep) = scratch("sweep");
    finished_sweep(&sweep);
    let before = contents(&sweep);
    let o = trace(StrategyName::Seq, &sweep, &[]);
    one_error_line(
        &o,
        "holds files that bench-sph trace did not write ('meta.json', ",
    );
    assert!(stderr(&o).contains("--force"), "{}", stderr(&o));
    let o = trace(StrategyName::Seq, &sweep, &["--force"]);
    one_error_line(
        &o,
        "meta.json': it exists and was not written by bench-sph trace",
    );
    assert_eq!(contents(&sweep), before, "nothing of the sweep changed");
}

#[test]
fn force_writes_beside_foreign_files_and_leaves_them_as_they_are() {
    let tmp = tempfile::tempdir().unwrap();
    std::fs::write(tmp.path().join("notes.txt"), "mine").unwrap();
    let o = trace(StrategyName::Seq, tmp.path(), &[]);
    one_error_line(&o, "('notes.txt')");
    let o = trace(StrategyName::Seq, tmp.path(), &["--force"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(
        names(tmp.path()),
        [
            "meta.json",
            "notes.txt",
            "stats.csv",
            "timeline.png",
            "trace.json"
        ]
    );
    assert_file_holds(&tmp.path().join("notes.txt"), "mine");
}

#[test]
fn a_second_trace_replaces_its_own_files_and_meta_json_names_the_tool_and_warm_up() {
    let tmp = tempfile::tempdir().unwrap();
    let o = trace(StrategyName::RayonChunks, tmp.path(), &["--warmup", "2"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let o = trace(StrategyName::Seq, tmp.path(), &["--warmup", "0"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let m = meta(tmp.path());
    assert_eq!(m["tool"], "bench-sph trace");
    assert_eq!(m["strategy"], "seq");
    assert_eq!(m["warmup_steps"], 0);
    assert_eq!(
        names(tmp.path()),
        ["meta.json", "stats.csv", "timeline.png", "trace.json"],
        "no temporary files remain"
    );
    assert!(stdout(&o).contains("2 steps recorded after 0 warm-up steps"));
}

#[test]
fn a_failed_trace_leaves_an_earlier_trace_in_its_directory_as_it_was() {
    let (tmp, out) = scratch("t");
    let o = trace(StrategyName::Seq, &out, &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    let before = contents(&out);
    let o = trace_diverging(tmp.path(), &out, &["--strategy", "seq"]);
    one_error_line(&o, "diverged at step 1");
    assert_eq!(contents(&out), before);
}

#[test]
fn a_trace_too_large_is_refused_before_it_runs_naming_the_estimate_and_what_to_lower() {
    let (_tmp, out) = scratch("big");
    let o = run(&[
        "trace",
        "--strategy",
        "rayon-spawn",
        "--n",
        "20000",
        "--steps",
        "50",
        "--out",
        out.to_str().unwrap(),
    ]);
    one_error_line(
        &o,
        "a trace of rayon-spawn with N = 20000 over 50 steps would record about 2000100 events \
         (about 340 MB of trace.json); the most is 1000000: lower --steps or --n",
    );
    assert!(!out.exists(), "nothing was created");
}

#[test]
fn when_only_one_of_two_workers_ran_kernels_the_summary_says_so_plainly() {
    let tmp = tempfile::tempdir().unwrap();
    // One particle: std-static makes one block per pass, so one of its two workers never
    // gets one.
    let o = run(&[
        "trace",
        "--strategy",
        "std-static",
        "--cores",
        "2",
        "--n",
        "1",
        "--out",
        tmp.path().to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let out = stdout(&o);
    assert!(
        out.contains(
            "\nonly 1 of 2 workers ran kernels in the recorded steps; the timeline does not \
             show parallel execution\n"
        ),
        "{out}"
    );
    assert_eq!(meta(tmp.path())["workers_used"], 1);
}

/// A copy of a real trace in `dir`.
fn real_trace(dir: &Path) {
    let o = trace(StrategyName::RayonChunks, dir, &[]);
    assert!(o.status.success(), "{}", stderr(&o));
}

fn report(results: &Path, extra: &[&str]) -> Output {
    let mut args = vec!["report", results.to_str().unwrap()];
    args.extend_from_slice(extra);
    run(&args)
}

#[test]
fn report_refuses_a_named_trace_directory_whose_timeline_is_not_a_png() {
    let (tmp, results) = scratch("results");
    finished_sweep(&results);
    let junk: PathBuf = tmp.path().join("junk");
    real_trace(&junk);
    std::fs::write(junk.join("timeline.png"), "not a png").unwrap();
    let o = report(&results, &["--trace", junk.to_str().unwrap()]);
    one_error_line(&o, "is not a valid trace: timeline.png is not a PNG image");
}

#[test]
fn report_skips_a_junk_trace_found_under_the_results_with_a_warning_and_embeds_a_good_one() {
    let (_tmp, results) = scratch("results");
    finished_sweep(&results);
    real_trace(&results.join("trace-good"));
    let junk = results.join("trace-junk");
    real_trace(&junk);
    std::fs::write(junk.join("stats.csv"), "kind,name\nnonsense,1\n").unwrap();
    let o = report(&results, &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    let err = stderr(&o);
    let warning = line_containing(&err, "trace-junk");
    assert!(
        warning.starts_with("warning: skipping trace directory '")
            && warning.ends_with("': stats.csv does not have the trace's columns (kind,name,threads,kernel_calls,busy_ms,span_ms,idle_pct,imbalance)"),
        "{warning}"
    );
    let md = std::fs::read_to_string(results.join("REPORT.md")).unwrap();
    assert!(md.contains("](trace-good/timeline.png)"), "{md}");
    assert!(!md.contains("trace-junk"), "{md}");
    let traces = &md[md.find("## Traces").unwrap()..];
    for number in traces
        .split(|c: char| !(c.is_ascii_digit() || c == '.'))
        .filter(|w| w.contains('.') && w.len() > 1)
    {
        let digits = number
            .trim_start_matches(['0', '.'])
            .chars()
            .filter(char::is_ascii_digit)
            .count();
        assert!(digits <= 3, "{number} has more than 3 significant digits");
    }
}
