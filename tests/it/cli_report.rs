//! `bench-sph report` driven through the built binary on a committed fixture results
//! directory (`tests/fixtures/report-results`: a tiny sweep under `--fake-timings` written
//! before rounds, so every number is known and the report must say how little it shows): every
//! chart is a PNG of the documented size, REPORT.md carries the fixture's numbers under a
//! banner and withholds its findings, a chart that does not apply is skipped and said so,
//! trace directories are embedded, bad input is one `Error: ...` line, and a sweep draws its own
//! report. Sweeps in rounds, with their confirmation, are made here by the binary under
//! `--fake-timings`: a finding appears only where the paired interval excludes 1, and which
//! runs chose and measured the best cells is said. No test asserts a duration.

use std::path::{Path, PathBuf};
use std::process::Output;

use crate::common::{
    assert_holds_all, fake_sweep, line_containing, png_size, run, scratch, sweep_into, text,
};

const WIDTH: u32 = 1000;
const HEIGHT: u32 = 650;

fn fixture() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/report-results")
}

/// Runs `report` and expects success.
fn report(args: &[&str]) -> Output {
    let mut all = vec!["report"];
    all.extend(args);
    let o = run(&all);
    assert!(
        o.status.success(),
        "{all:?}:\n{}\n{}",
        text(&o.stdout),
        text(&o.stderr)
    );
    o
}

/// Runs `report` and expects a single `Error: ...` line containing `needle`.
fn report_fails(args: &[&str], needle: &str) {
    let mut all = vec!["report"];
    all.extend(args);
    let o = run(&all);
    let err = text(&o.stderr);
    assert!(!o.status.success(), "{all:?} succeeded");
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.starts_with("Error: ") && err.contains(needle), "{err}");
}

fn pngs(dir: &Path) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "png"))
        .collect();
    v.sort();
    v
}

/// A copy of the fixture's meta.json and only the summary rows for which `keep` holds.
fn filtered_fixture(dir: &Path, keep: impl Fn(&str) -> bool) {
    std::fs::create_dir_all(dir).unwrap();
    std::fs::copy(fixture().join("meta.json"), dir.join("meta.json")).unwrap();
    let summary = std::fs::read_to_string(fixture().join("summary.csv")).unwrap();
    let mut lines = summary.lines();
    let mut out = format!("{}\n", lines.next().unwrap());
    for l in lines.filter(|l| keep(l)) {
        out.push_str(l);
        out.push('\n');
    }
    std::fs::write(dir.join("summary.csv"), out).unwrap();
}

#[test]
fn every_chart_of_the_fixture_is_a_png_of_the_documented_size() {
    let out = tempfile::tempdir().unwrap();
    let o = report(&[
        fixture().to_str().unwrap(),
        "--out",
        out.path().to_str().unwrap(),
    ]);
    let files = pngs(out.path());
    // Per group (4): charts 1 and 2 for 2 chunked strategies, chart 3 for 3 strategies,
    // charts 4 and 5; chart 6 once for the preset.
    assert_eq!(files.len(), 4 * (2 * 2 + 3 + 2) + 1, "{files:?}");
    for name in [
        "seed-all-pairs-n60-s3-1-runtime-vs-chunks-rayon-chunks.png",
        "seed-all-pairs-n60-s3-2-cpu-vs-chunks-crossbeam-pool.png",
        "seed-grid-n120-s3-3-best-rayon-iter.png",
        "seed-all-pairs-n120-s3-4-speedup.png",
        "seed-grid-n60-s3-5-efficiency.png",
        "seed-6-neighbors.png",
    ] {
        assert!(out.path().join(name).is_file(), "{name} missing");
    }
    for f in &files {
        assert_eq!(png_size(f), (WIDTH, HEIGHT), "{}", f.display());
        assert!(
            text(&o.stdout).contains(&f.display().to_string()),
            "{} not listed",
            f.display()
        );
    }
    let md = std::fs::read_to_string(out.path().join("REPORT.md")).unwrap();
    for f in &files {
        let name = f.file_name().unwrap().to_str().unwrap();
        assert!(md.contains(&format!("]({name})")), "{name} not embedded");
    }
}

#[test]
fn an_older_directory_is_shown_as_measured_under_a_banner_and_its_findings_are_withheld() {
    let out = tempfile::tempdir().unwrap();
    report(&[
        fixture().to_str().unwrap(),
        "--out",
        out.path().to_str().unwrap(),
    ]);
    let md = std::fs::read_to_string(out.path().join("REPORT.md")).unwrap();
    let needles = [
        "| CPU |",
        "| hardware threads | 2 |",
        "--fake-timings",
        "## seed preset, all-pairs, N = 60, 3 steps",
        "Reference: `seq` at 1 core, 2.00 ± 0.04 s over 3 trials.",
        // rayon-chunks, all-pairs N = 60: best cells (mean, median, fastest) beside the
        // paper's Table 1 (at most three significant digits, the paper's numbers too).
        "| 2 | 2 | 1.09 | 1.09 | 1.07 | 1.84× | 0.919 | 45 | 14.9 | 2.00× |",
        "| 3 ⚠ oversubscribed | 5 | 1.31 | 1.31 | 1.28 | 1.53× | 0.509 | 90 | 10.4 | 2.87× |",
        "| 6 | — | — | — | — | — | — | 150 | 5.82 | 5.13× |",
        // rayon-iter has no chunks and so no paper columns.
        "| 2 | — | 1.14 | 1.14 | 1.12 | 1.75× | 0.874 |",
        // The grid groups are not comparable with the paper: plain tables.
        "| 2 | 2 | 0.544 | 0.544 | 0.533 | 1.84× | 0.919 |",
        "Speedups compare; absolute times do not",
        "No cell failed: every cell reproduced its group's `seq` checksum.",
        // What the tool does not know, said before any number.
        "> ⚠ **Measured before rounds**",
        "percentile-bootstrap intervals that under-cover (about 80 % of them hold the true \
         value at 5 trials, not 95 %",
        "speedups that divide two means rather than pair the runs of a round",
        "- Findings withheld: this sweep was measured before rounds",
        "the same 3 rounds of the grid (no confirmation rounds: the sweep was written before \
         they existed)",
    ];
    assert_holds_all("REPORT.md", &md, &needles);
    assert!(
        md.find("Measured before rounds").unwrap() < md.find("## Machine and build").unwrap(),
        "{md}"
    );
    // Four groups, each with its findings withheld; no winner, no serial fraction.
    assert_eq!(md.matches("- Findings withheld").count(), 4, "{md}");
    for absent in [
        "is fastest",
        "not distinguishable",
        "Karp–Flatt serial fraction of",
    ] {
        assert!(!md.contains(absent), "{absent}:\n{md}");
    }
}

/// Fake times of `fake_sweep`'s plan (seq, rayon-iter at 1 and 2 cores, rayon-chunks with 4
/// chunks at 1 and 2 cores), round by round: every cell drifts alike from round to round
/// (×1, ×1.3, ×0.8), rayon-chunks at 2 cores takes `chunks_2`. The run of cell c in round r
/// gets item 3c + r − 1 (the confirmation's runs the same items again: the list repeats).
fn drifting(chunks_2: [f64; 3]) -> String {
    let drift = [1.0, 1.3, 0.8];
    let mut times: Vec<f64> = Vec::new();
    for mean in [1.0, 1.02, 0.6, 1.03] {
        times.extend(drift.iter().map(|d| mean * d));
    }
    times.extend(chunks_2);
    let times: Vec<String> = times.iter().map(|t| format!("{t:.4}")).collect();
    times.join(",")
}

/// A fake sweep of `drifting(chunks_2)` with `extra` options, reported; returns REPORT.md.
fn drifting_report(chunks_2: [f64; 3], extra: &[&str]) -> String {
    let (_tmp, dir) = scratch("results");
    let timings = drifting(chunks_2);
    let mut args = fake_sweep("rayon-chunks,rayon-iter", &timings);
    args.extend(extra);
    args.extend(["--no-plots", "--out", dir.to_str().unwrap()]);
    let o = run(&args);
    assert!(o.status.success(), "{}", text(&o.stderr));
    report(&[dir.to_str().unwrap()]);
    std::fs::read_to_string(dir.join("REPORT.md")).unwrap()
}

#[test]
fn a_strategy_is_called_fastest_only_where_its_paired_interval_excludes_one() {
    // rayon-chunks takes 5 % longer than rayon-iter in every round: the drift (±30 %) makes
    // each cell's own interval far wider than that, but their per-round ratio is steady.
    let md = drifting_report([0.63, 0.819, 0.504], &[]);
    assert_holds_all(
        "REPORT.md",
        &md,
        &[
            "was chosen by the grid's 3 rounds and measured again in 3 rounds of confirmation \
             with `seq`",
            "- At 2 cores, **rayon-iter (0.620 s [",
            "is fastest, 1.67 ± 0.00× over seq: it is 1.05 ± 0.00× faster than the runner-up \
             rayon-chunks with 4 chunks (0.651 s [",
            "e = 0.200 [0.200–0.200]",
            "| 2 | — | 0.620 [",
        ],
    );
    // The same means, but rounds that disagree: no winner.
    let md = drifting_report([0.66, 0.76, 0.52], &[]);
    let at_two = line_containing(&md, "- At 2 cores");
    assert!(
        at_two.contains("are not distinguishable") && !at_two.contains("fastest"),
        "{at_two}"
    );
}

#[test]
fn best_cells_without_confirmation_rounds_are_said_to_be_biased_fast() {
    let md = drifting_report([0.63, 0.819, 0.504], &["--confirm-rounds", "0"]);
    let note = line_containing(&md, "**Best cells biased fast**");
    assert!(
        note.contains("chosen and measured by the same 3 rounds of the grid")
            && note.contains("the sweep ran with `--confirm-rounds 0`"),
        "{note}"
    );
    assert!(!md.contains("rounds of confirmation"), "{md}");
}

#[test]
fn a_results_directory_with_one_neighbour_search_skips_chart_six_and_says_so() {
    let (_tmp, dir) = scratch("results");
    filtered_fixture(&dir, |l| l.contains(",all-pairs,seed,60,"));
    report(&[dir.to_str().unwrap()]);
    assert!(!dir.join("seed-6-neighbors.png").exists());
    assert_eq!(pngs(&dir).len(), 2 * 2 + 3 + 2);
    let md = std::fs::read_to_string(dir.join("REPORT.md")).unwrap();
    assert!(
        md.contains("Chart 6 (all-pairs against grid) is not drawn for the seed preset"),
        "{md}"
    );
}

#[test]
fn a_single_core_count_skips_the_charts_against_cores_and_says_so() {
    let (_tmp, dir) = scratch("results");
    filtered_fixture(&dir, |l| l.contains(",grid,seed,60,3,1,"));
    report(&[dir.to_str().unwrap()]);
    let md = std::fs::read_to_string(dir.join("REPORT.md")).unwrap();
    assert!(
        md.contains("Charts 3–5 (against cores) are not drawn: only 1 core was measured."),
        "{md}"
    );
    assert_eq!(pngs(&dir).len(), 2 * 2);
}

#[test]
fn trace_directories_under_the_results_or_given_with_trace_are_embedded() {
    let (tmp, dir) = scratch("results");
    filtered_fixture(&dir, |l| l.contains(",all-pairs,seed,60,"));
    let stats = "kind,name,threads,kernel_calls,busy_ms,span_ms,idle_pct,imbalance\n\
                 worker,0,1,90,10.0,12.0,16.7,\nworker,1,1,90,9.0,12.0,25.0,\n\
                 pass,density,,90,9.5,5.0,5.0,1.10\ntotal,all,2,180,19.0,12.0,20.8,\n";
    let meta = r#"{"tool":"bench-sph trace","strategy":"rayon-chunks","cores":2,"chunks":45,
        "n":1000,"steps":3,"preset":"seed","neighbors":"all-pairs","seed":2019,"init":null,
        "warmup_steps":5,"wall_s":0.1,"cpu_s":0.2,"kernel_calls":180,"worker_threads":2,
        "workers_used":2,"checksum":"00000000000000aa","timeline_steps":[1,3],"simd":"portable",
        "pin":"none"}"#;
    for t in [dir.join("trace-inside"), tmp.path().join("trace-outside")] {
        std::fs::create_dir_all(&t).unwrap();
        // Only the PNG header is read: the signature, and the size (a timeline is 1600 wide).
        let mut png = b"\x89PNG\r\n\x1a\n\0\0\0\x0dIHDR".to_vec();
        png.extend(1600u32.to_be_bytes());
        png.extend(300u32.to_be_bytes());
        std::fs::write(t.join("timeline.png"), png).unwrap();
        std::fs::write(t.join("stats.csv"), stats).unwrap();
        std::fs::write(t.join("meta.json"), meta).unwrap();
    }
    let outside = tmp.path().join("trace-outside");
    report(&[dir.to_str().unwrap(), "--trace", outside.to_str().unwrap()]);
    let md = std::fs::read_to_string(dir.join("REPORT.md")).unwrap();
    assert!(md.contains("## Traces"), "{md}");
    assert!(md.contains("](trace-inside/timeline.png)"), "{md}");
    assert!(md.contains("](trace-outside-timeline.png)"), "{md}");
    assert!(dir.join("trace-outside-timeline.png").is_file());
    assert!(
        md.contains("| density | 90 | 9.50 | 5.00 | 5.00 | 1.10 |"),
        "{md}"
    );
    report_fails(
        &[
            dir.to_str().unwrap(),
            "--trace",
            tmp.path().to_str().unwrap(),
        ],
        "is not a trace directory",
    );
}

#[test]
fn a_missing_or_garbled_summary_or_meta_is_one_error_line_and_a_failure() {
    let (_tmp, dir) = scratch("results");
    let d = dir.to_str().unwrap();
    report_fails(&[d], "does not exist");
    filtered_fixture(&dir, |_| true);
    std::fs::remove_file(dir.join("summary.csv")).unwrap();
    report_fails(&[d], "summary.csv");
    filtered_fixture(&dir, |_| true);
    std::fs::write(dir.join("summary.csv"), "strategy,cores\nseq,1\n").unwrap();
    report_fails(&[d], "is not a bench-sph summary.csv");
    filtered_fixture(&dir, |_| true);
    std::fs::write(dir.join("meta.json"), "{ not json").unwrap();
    report_fails(&[d], "meta.json");
    assert!(!dir.join("REPORT.md").exists());
}

#[test]
fn a_sweep_without_no_plots_writes_its_charts_and_report() {
    let (_tmp, dir) = scratch("sweep");
    let o = sweep_into(
        &dir,
        "--strategies rayon-chunks --cores 1..2 --chunks 2,5 --n 60 --steps 3 --trials 2 \
         --warmup 0",
    );
    assert!(
        o.status.success(),
        "{}\n{}",
        text(&o.stdout),
        text(&o.stderr)
    );
    assert!(text(&o.stdout).contains("REPORT.md"), "{}", text(&o.stdout));
    let md = std::fs::read_to_string(dir.join("REPORT.md")).unwrap();
    assert!(md.contains("**rayon-chunks**"), "{md}");
    // Two rounds give no interval, so no finding, and the report says so.
    assert!(
        md.contains(
            "- No finding: these cells ran 2 rounds, and an interval, so a finding, \
                     needs 3 or more"
        ),
        "{md}"
    );
    assert!(
        !md.contains("is fastest") && !md.contains("not distinguishable"),
        "{md}"
    );
    for name in [
        "seed-all-pairs-n60-s3-1-runtime-vs-chunks-rayon-chunks.png",
        "seed-all-pairs-n60-s3-4-speedup.png",
    ] {
        assert_eq!(png_size(&dir.join(name)), (WIDTH, HEIGHT), "{name}");
    }
}

#[test]
fn a_toy_and_a_wcsph_sweep_get_a_ranking_comparison_and_one_preset_alone_does_not() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = |name: &str| tmp.path().join(name);
    // Cells in plan order: seq, rayon-chunks at 1 and 2 cores, std-static at 1 and 2 cores,
    // three trials each. At 2 cores rayon-chunks wins the toy workload and std-static wcsph,
    // both well beyond the trial spread.
    let (fast, slow) = ("0.5,0.51,0.49", "0.7,0.71,0.69");
    let one_core = "1.0,1.02,0.98";
    for (name, preset, n, rayon, static_) in [
        ("toy", "seed", 200, fast, slow),
        ("wcsph", "wcsph", 128, slow, fast),
    ] {
        let timings = [one_core, one_core, rayon, one_core, static_].join(",");
        let o = sweep_into(
            &dir(name),
            &format!(
                "--preset {preset} --neighbors grid --n {n} --steps 3 --trials 3 --warmup 0 \
                 --cores 1..2 --chunks 4 --strategies rayon-chunks,std-static --no-plots \
                 --fake-timings {timings}"
            ),
        );
        assert!(
            o.status.success(),
            "{}\n{}",
            text(&o.stdout),
            text(&o.stderr)
        );
    }
    let path = |name: &str| dir(name).to_str().unwrap().to_owned();
    report(&[&path("toy"), &path("wcsph"), "--out", &path("both")]);
    let md = std::fs::read_to_string(dir("both").join("REPORT.md")).unwrap();
    assert_holds_all(
        "REPORT.md",
        &md,
        &[
            "## Toy vs real workload: does the ranking hold?",
            "### wcsph preset, grid, N = 128, 3 steps against seed preset, grid, N = 200, 3 steps",
            "| rayon-chunks | 1 · 2.00 ± 0.00×",
            "At 2 cores, the winner changes: **rayon-chunks** is fastest on the toy workload \
             and **std-static** on wcsph",
            "Moved up on wcsph, both orders resolved by their paired rounds: std-static (past \
             rayon-chunks); moved down: rayon-chunks.",
            "## wcsph preset, grid, N = 128, 3 steps",
        ],
    );
    for alone in ["toy", "wcsph"] {
        let out = format!("{alone}-alone");
        report(&[&path(alone), "--out", &path(&out)]);
        let md = std::fs::read_to_string(dir(&out).join("REPORT.md")).unwrap();
        assert!(!md.contains("Toy vs real workload"), "{md}");
    }
}
