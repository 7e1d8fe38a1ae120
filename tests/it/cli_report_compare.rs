//! `bench-sph report` on results directories of different machines, driven through the built
//! binary on small sweeps under `--fake-timings` (every number known): the machines are
//! compared side by side and never pooled, the same cell on two machines is no repeat,
//! `--compare` sets directories of one machine apart and says so, directories of one machine
//! without it are one pooled study as before, steps that differ are said, and the comparison's
//! charts and a normal report's replace each other in one directory; two sweeps of one
//! machine set apart by `--compare` get a reproducibility section that lists every ranking
//! the second reversed. A machine is made "another" by editing `cpu_model` in a copy's
//! `meta.json`. No test asserts a duration.

use std::path::{Path, PathBuf};

use crate::common;
use crate::common::{
    assert_holds_all, fails_with, fake_sweep, line_containing, names, read_json, run, text,
};

const WIDTH: u32 = 1000;
const HEIGHT: u32 = 650;
/// Where the legend panel starts: every pixel left of it is the plot.
const PLOT_WIDTH: u32 = 750;
/// The colours of sides A and B (the charts' palette, Tableau 10).
const SIDE_COLOURS: [[u8; 3]; 2] = [[31, 119, 180], [255, 127, 14]];

/// Fake times of the plan (registry order) seq, rayon-iter at 1 and 2 cores, rayon-chunks at
/// 1 and 2 cores, three trials each, where rayon-chunks wins at 2 cores (0.5 s against
/// 0.7 s: the trial spread is ±2 %, so the intervals are far apart).
const CHUNKS_WIN: &str = "1.0,1.02,0.98,1.0,1.02,0.98,0.7,0.71,0.69,1.0,1.02,0.98,0.5,0.51,0.49";
/// The same plan where rayon-iter wins at 2 cores.
const ITER_WINS: &str = "1.0,1.02,0.98,1.0,1.02,0.98,0.5,0.51,0.49,1.0,1.02,0.98,0.7,0.71,0.69";

/// A finished fake sweep of seq, rayon-chunks and rayon-iter into `dir` (N = 60, 3 steps,
/// 1 and 2 cores, 4 chunks), with each `(option, value)` of `set` replacing the default's.
fn sweep(dir: &Path, timings: &str, set: &[(&str, &str)]) {
    let mut args = fake_sweep("rayon-chunks,rayon-iter", timings);
    for (option, value) in set {
        let at = args.iter().position(|a| a == option).unwrap();
        args[at + 1] = value;
    }
    args.extend(["--no-plots", "--out", dir.to_str().unwrap()]);
    let o = run(&args);
    assert!(o.status.success(), "{args:?}: {}", text(&o.stderr));
}

/// Makes the sweep in `dir` look measured on a machine whose CPU is `cpu`.
fn move_to_machine(dir: &Path, cpu: &str) {
    common::set_in_meta(dir, |m| m["machine"]["cpu_model"] = cpu.into());
}

/// The label of the machine in `dir`'s meta.json, as the report names it.
fn machine_label(dir: &Path) -> String {
    let meta = read_json(&dir.join("meta.json"));
    let threads = meta["machine"]["hardware_threads"].as_u64().unwrap();
    format!(
        "{}, {threads} hardware thread{}",
        meta["machine"]["cpu_model"].as_str().unwrap(),
        if threads == 1 { "" } else { "s" }
    )
}

/// Runs `report` on `dirs` into `out` with `extra`, expecting success; returns REPORT.md.
fn report(dirs: &[&Path], out: &Path, extra: &[&str]) -> String {
    let mut args = vec!["report"];
    args.extend(dirs.iter().map(|d| d.to_str().unwrap()));
    args.extend(["--out", out.to_str().unwrap()]);
    args.extend(extra);
    let o = run(&args);
    assert!(o.status.success(), "{args:?}: {}", text(&o.stderr));
    std::fs::read_to_string(out.join("REPORT.md")).unwrap()
}

/// The PNGs of `dir`, by name.
fn pngs(dir: &Path) -> Vec<String> {
    names(dir)
        .into_iter()
        .filter(|n| n.ends_with(".png"))
        .collect()
}

/// The size of the PNG at `path`, and which of [`SIDE_COLOURS`] its plot area holds.
fn chart_facts(path: &Path) -> ((u32, u32), [bool; 2]) {
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(path).unwrap()));
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut buf).unwrap();
    let width = info.width as usize;
    let mut seen = [false; 2];
    for (i, px) in buf[..info.buffer_size()].chunks(3).enumerate() {
        if (i % width) < PLOT_WIDTH as usize {
            for (side, colour) in SIDE_COLOURS.iter().enumerate() {
                seen[side] |= px == colour;
            }
        }
    }
    ((info.width, info.height), seen)
}

/// Two sweeps of the same plan in `root`: `a` on this machine, `b` on "Test CPU B".
fn two_machines(root: &Path) -> (PathBuf, PathBuf) {
    let (a, b) = (root.join("a"), root.join("b"));
    sweep(&a, CHUNKS_WIN, &[]);
    sweep(&b, ITER_WINS, &[]);
    move_to_machine(&b, "Test CPU B");
    (a, b)
}

#[test]
fn two_machines_are_compared_side_by_side_and_their_shared_cells_are_not_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let (a, b) = two_machines(tmp.path());
    let out = tmp.path().join("out");
    let md = report(&[&a, &b], &out, &[]);
    let a_label = machine_label(&a);
    assert_holds_all(
        "REPORT.md",
        &md,
        &[
            "# bench-sph report: machines compared",
            "on 2 sides",
            "**Test data**",
            &format!("| A | {a_label} |"),
            "| B | Test CPU B, 2 hardware threads |",
            "## Comparing machines",
            "### seed preset, all-pairs, N = 60, 3 steps",
            "**Best strategy per machine**",
            "The fastest strategy depends on the machine: A **rayon-chunks**, B **rayon-iter**",
            &format!("## A: {a_label}"),
            "## B: Test CPU B, 2 hardware threads",
            &format!("run `bench-sph report {}`", b.display()),
        ],
    );
    // One row per machine in the best-strategy table, each resolved by its intervals.
    let row_a = line_containing(&md, "| A | 3 |");
    assert!(
        row_a.starts_with("| A | 3 | rayon-chunks | 2 | 4 | 0.500 [")
            && row_a.contains("resolved: 1.40 ± 0.02× faster than the next fastest, rayon-iter"),
        "{row_a}"
    );
    let row_b = line_containing(&md, "| B | 3 |");
    assert!(
        row_b.starts_with("| B | 3 | rayon-iter | 2 | — | 0.500 [")
            && row_b.contains("faster than the next fastest, rayon-chunks"),
        "{row_b}"
    );
    // Not pooled: no study section of a single machine, no chart of a normal report.
    assert!(!md.contains("\n## seed preset") && !md.contains("Best cell per core count"));
    assert!(!md.contains("is in both"));
    let charts = pngs(&out);
    assert_eq!(
        charts,
        [
            "compare-seed-all-pairs-n60-s3-rayon-chunks.png",
            "compare-seed-all-pairs-n60-s3-rayon-iter.png"
        ]
    );
    for name in &charts {
        assert!(md.contains(&format!("]({name})")), "{name} not embedded");
        // One line per machine: both sides' colours are drawn in the plot.
        assert_eq!(
            chart_facts(&out.join(name)),
            ((WIDTH, HEIGHT), [true, true]),
            "{name}"
        );
    }
}

#[test]
fn compare_on_one_machine_sets_each_directory_apart_and_says_loudly_it_is_one_machine() {
    let tmp = tempfile::tempdir().unwrap();
    let (a, b) = (tmp.path().join("a"), tmp.path().join("b"));
    sweep(&a, CHUNKS_WIN, &[]);
    sweep(&b, ITER_WINS, &[]);
    let out = tmp.path().join("out");
    let md = report(&[&a, &b], &out, &["--compare"]);
    let label = machine_label(&a);
    let banner = line_containing(&md, "⚠ **All sides ran on the same machine**");
    assert!(
        banner.contains(&label) && banner.contains("**not differences between machines**"),
        "{banner}"
    );
    assert!(md.find(banner).unwrap() < md.find("## Comparing machines").unwrap());
    assert_holds_all(
        "REPORT.md",
        &md,
        &[
            &format!("## A: {label} (a)"),
            &format!("## B: {label} (b)"),
            &format!("run `bench-sph report {}`", b.display()),
            "| A | 3 | rayon-chunks |",
            "| B | 3 | rayon-iter |",
        ],
    );
    assert_eq!(pngs(&out).len(), 2, "{:?}", pngs(&out));
    // The second sweep reversed the first's ranking at 2 cores: listed, with each side's
    // paired ratio. At 1 core the two strategies' times are equal on both sides: not
    // resolved on either, so not a ranking.
    let section = md.find("## Reproducibility: B against A").unwrap();
    assert!(section < md.find("## Comparing machines").unwrap());
    assert_holds_all(
        "REPORT.md",
        &md,
        &[
            "A and B ran on the same machine, so B is a second measurement of what A measured. \
             Of the 10 cells both measured (matched by cell and phase), the 95 % speedup \
             intervals overlap in 6 of 10 (60.0 %)",
            "resolved on either side: 1; reversed on the other: 1; resolved on one side only: 0.",
            "| seed preset, all-pairs, N = 60, 3 steps | 2 | rayon-iter | 1.40 ± 0.02× slower \
             than rayon-chunks | 1.40 ± 0.02× faster than rayon-chunks | **reversed** |",
        ],
    );
    let o = run(&["report", a.to_str().unwrap(), "--compare"]);
    assert!(!o.status.success());
    assert!(
        text(&o.stderr).contains("--compare needs two results directories or more"),
        "{}",
        text(&o.stderr)
    );
}

#[test]
fn directories_of_one_machine_without_compare_stay_one_pooled_study() {
    let tmp = tempfile::tempdir().unwrap();
    let (a, b) = (tmp.path().join("a"), tmp.path().join("b"));
    sweep(&a, CHUNKS_WIN, &[]);
    sweep(&b, ITER_WINS, &[("--n", "120")]);
    let out = tmp.path().join("out");
    let md = report(&[&a, &b], &out, &[]);
    assert!(md.starts_with("# bench-sph report\n"), "{md}");
    assert_holds_all(
        "REPORT.md",
        &md,
        &[
            ": 10 cells in 2 groups.",
            "## Machine and build",
            "## seed preset, all-pairs, N = 60, 3 steps",
            "## seed preset, all-pairs, N = 120, 3 steps",
            "### Best cell per core count (Table 1 analogue)",
        ],
    );
    assert!(!md.contains("machines compared") && !md.contains("Comparing machines"));
    let charts = pngs(&out);
    assert!(charts.iter().all(|c| c.starts_with("seed-")), "{charts:?}");
    assert!(charts.contains(&"seed-all-pairs-n120-s3-4-speedup.png".to_owned()));

    // The same cells in two directories of one machine are still refused, even beside a
    // directory of another machine.
    let c = tmp.path().join("c");
    sweep(&c, CHUNKS_WIN, &[]);
    let d = tmp.path().join("d");
    sweep(&d, ITER_WINS, &[]);
    move_to_machine(&d, "Test CPU D");
    let args = [
        a.to_str().unwrap(),
        c.to_str().unwrap(),
        d.to_str().unwrap(),
    ];
    let o = run(&[
        "report",
        args[0],
        args[1],
        args[2],
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(!o.status.success());
    assert!(
        text(&o.stderr).contains("is in both"),
        "{}",
        text(&o.stderr)
    );
}

#[test]
fn steps_that_differ_between_machines_are_said_with_the_steps_of_each_side() {
    let tmp = tempfile::tempdir().unwrap();
    let (a, b) = (tmp.path().join("a"), tmp.path().join("b"));
    sweep(&a, CHUNKS_WIN, &[]);
    sweep(&b, ITER_WINS, &[("--steps", "4")]);
    move_to_machine(&b, "Test CPU B");
    let out = tmp.path().join("out");
    let md = report(&[&a, &b], &out, &[]);
    assert_holds_all(
        "REPORT.md",
        &md,
        &[
            "### seed preset, all-pairs, N = 60; steps differ: A 3, B 4",
            "> ⚠ **Steps differ** (A 3, B 4): speedup and efficiency still compare",
            "**absolute times do not**, and none are compared here",
            "| A | 3 | rayon-chunks |",
            "| B | 4 | rayon-iter |",
        ],
    );
    assert_eq!(
        pngs(&out),
        [
            "compare-seed-all-pairs-n60-s3-s4-rayon-chunks.png",
            "compare-seed-all-pairs-n60-s3-s4-rayon-iter.png"
        ]
    );
}

#[test]
fn a_partial_side_keeps_its_banner_and_a_group_of_one_side_is_listed_as_not_compared() {
    let tmp = tempfile::tempdir().unwrap();
    let (a, b) = (tmp.path().join("a"), tmp.path().join("b"));
    sweep(&a, CHUNKS_WIN, &[("--n", "60,120")]);
    // B measures rayon-iter only, and stops after its grid's 9 runs: no confirmation.
    let mut args = fake_sweep("rayon-iter", ITER_WINS);
    args.extend(["--no-plots", "--stop-after-runs", "9"]);
    args.extend(["--out", b.to_str().unwrap()]);
    assert!(!run(&args).status.success(), "the sweep stops early");
    move_to_machine(&b, "Test CPU B");
    let out = tmp.path().join("out");
    let md = report(&[&a, &b], &out, &[]);
    let banner = line_containing(&md, "Partial study");
    assert!(banner.contains(&format!("`{}`", b.display())), "{banner}");
    assert!(md.find(banner).unwrap() < md.find("## Machines").unwrap());
    assert_holds_all(
        "REPORT.md",
        &md,
        &[
            "### Measured on one side only",
            "- A: seed preset, all-pairs, N = 120, 3 steps",
            // B measured rayon-iter only: one line per machine for it, none for rayon-chunks.
            "- rayon-chunks: speedups on A only: nothing to compare, no chart.",
            "| B | 3 | rayon-iter | 2 | — |",
        ],
    );
    assert!(line_containing(&md, "| B | 3 |").contains("only one strategy measured"));
    assert_eq!(pngs(&out), ["compare-seed-all-pairs-n60-s3-rayon-iter.png"]);
}

#[test]
fn a_normal_report_and_a_comparison_replace_each_others_charts_in_one_directory() {
    let tmp = tempfile::tempdir().unwrap();
    let (a, b) = two_machines(tmp.path());
    let out = tmp.path().join("out");
    report(&[&a, &b], &out, &[]);
    assert!(pngs(&out).iter().all(|c| c.starts_with("compare-")));
    // The comparison's files are the report's own: no --force needed, and none stay.
    let md = report(&[&a], &out, &[]);
    assert!(md.starts_with("# bench-sph report\n"));
    let charts = pngs(&out);
    assert!(
        !charts.is_empty() && charts.iter().all(|c| c.starts_with("seed-")),
        "{charts:?}"
    );
    report(&[&a, &b], &out, &[]);
    assert!(
        pngs(&out).iter().all(|c| c.starts_with("compare-")),
        "{:?}",
        pngs(&out)
    );
}

#[test]
fn a_comparison_is_never_written_over_one_compared_directorys_own_report() {
    let tmp = tempfile::tempdir().unwrap();
    let (a, b) = two_machines(tmp.path());
    let before = names(&a);
    for extra in [&[][..], &["--out", a.to_str().unwrap()][..]] {
        let mut args = vec!["report", a.to_str().unwrap(), b.to_str().unwrap()];
        args.extend(extra);
        fails_with(&args, &["compared, not pooled", "--out DIR"]);
        assert_eq!(
            names(&a),
            before,
            "nothing written into a compared directory"
        );
    }
}
