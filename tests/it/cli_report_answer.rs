//! REPORT.md answers first (issue 43, item 8): under the build line, `## The answer` names per
//! group and core count the strategy with the lowest mean, in bold only where the group's own
//! findings call it fastest, "not resolved" where they find it not distinguishable, and for a
//! group whose findings are withheld, the reason — all before the method and the machine
//! table, under the banners that qualify every number. Driven through the built binary on
//! sweeps timed by `--fake-timings` and on the committed fixture `tests/fixtures/report-results`.

use std::path::{Path, PathBuf};

use crate::common::{fake_sweep, run, scratch, text};

fn fixture() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/report-results")
}

/// Reports `dirs` into `out` (no charts asked of the sweep; the report draws its own) and
/// returns REPORT.md.
fn report_md(dirs: &[&Path], out: &Path) -> String {
    let mut args: Vec<&str> = vec!["report"];
    args.extend(dirs.iter().map(|d| d.to_str().unwrap()));
    args.extend(["--out", out.to_str().unwrap()]);
    let o = run(&args);
    assert!(o.status.success(), "{args:?}: {}", text(&o.stderr));
    std::fs::read_to_string(out.join("REPORT.md")).unwrap()
}

/// A fake sweep of `fake_sweep`'s plan (seq, rayon-iter and rayon-chunks with 4 chunks, at 1
/// and 2 cores), every cell drifting alike from round to round (×1, ×1.3, ×0.8), rayon-chunks
/// at 2 cores taking `chunks_2`; reported, its REPORT.md.
fn drifting_report(chunks_2: [f64; 3]) -> String {
    let (_tmp, dir) = scratch("results");
    let drift = [1.0, 1.3, 0.8];
    let mut times: Vec<f64> = Vec::new();
    for mean in [1.0, 1.02, 0.6, 1.03] {
        times.extend(drift.iter().map(|d| mean * d));
    }
    times.extend(chunks_2);
    let timings: Vec<String> = times.iter().map(|t| format!("{t:.4}")).collect();
    let timings = timings.join(",");
    let mut args = fake_sweep("rayon-chunks,rayon-iter", &timings);
    args.extend(["--no-plots", "--out", dir.to_str().unwrap()]);
    let o = run(&args);
    assert!(o.status.success(), "{}", text(&o.stderr));
    report_md(&[&dir], &dir)
}

/// The answer section: from its heading to the next `## `.
fn answer(md: &str) -> &str {
    let from = md.find("## The answer").expect("an answer section");
    let rest = &md[from + 3..];
    &md[from..from + 3 + rest.find("\n## ").unwrap_or(rest.len())]
}

/// The answer's row for group `label` at `cores`.
fn row<'a>(md: &'a str, label: &str, cores: usize) -> &'a str {
    answer(md)
        .lines()
        .find(|l| {
            l.starts_with(&format!("| {label}"))
                && l.split(" | ").nth(1).is_some_and(|c| {
                    c.split_whitespace().next() == Some(cores.to_string().as_str())
                })
        })
        .unwrap_or_else(|| panic!("no answer row for {label} at {cores}:\n{md}"))
}

/// Checks every group's answer rows against its own findings: where a finding calls
/// `**X with K chunks (…)**` fastest at c cores the row names `**X, K chunks**` in bold,
/// where the finding says "not distinguishable" the row says *not resolved* and has no bold.
/// Returns how many rows it checked.
fn answer_agrees_with_findings(md: &str) -> usize {
    let mut checked = 0;
    for section in md.split("\n## ").skip(1) {
        let label = section.lines().next().unwrap();
        let Some(found) = section.split("### Findings").nth(1) else {
            continue;
        };
        for f in found.lines().filter_map(|l| l.strip_prefix("- At ")) {
            let Some((cores, rest)) = f.split_once(' ') else {
                continue;
            };
            let Ok(cores) = cores.parse::<usize>() else {
                continue;
            };
            if rest.starts_with("core, where every strategy does seq's work") {
                continue;
            }
            let answered = row(md, label, cores);
            if let Some(winner) = rest
                .split("**")
                .nth(1)
                .filter(|_| rest.contains("is fastest"))
            {
                let named = winner.split(" (").next().unwrap().replace(" with ", ", ");
                assert!(
                    answered.contains(&format!("| **{named}** |"))
                        && answered.contains(" faster than "),
                    "{f}\n{answered}"
                );
            } else if rest.contains("are not distinguishable") {
                assert!(
                    answered.contains("*not resolved* against") && !answered.contains("**"),
                    "{f}\n{answered}"
                );
            } else if rest.contains(", only ") {
                assert!(
                    answered.contains("the only strategy measured"),
                    "{f}\n{answered}"
                );
            }
            checked += 1;
        }
    }
    checked
}

#[test]
fn the_answer_comes_first_and_names_the_fastest_as_the_findings_do() {
    // rayon-chunks takes 5 % longer than rayon-iter in every round at 2 cores: resolved.
    let md = drifting_report([0.63, 0.819, 0.504]);
    let at = |needle: &str| md.find(needle).unwrap_or_else(|| panic!("{needle}:\n{md}"));
    assert!(at("(build ") < at("## The answer"));
    assert!(at("## The answer") < at("**Method.**"));
    assert!(at("**Method.**") < at("## Machine and build"));
    assert!(at("## Machine and build") < at("### Findings"));
    let label = "seed preset, all-pairs, N = 60, 3 steps";
    assert_eq!(
        row(&md, label, 2),
        format!(
            "| {label} | 2 | **rayon-iter** | 1.67 ± 0.00× | 1.05 ± 0.00× faster than \
             rayon-chunks, 4 chunks |"
        )
    );
    assert_eq!(answer_agrees_with_findings(&md), 2);
    // Within the first screen.
    let first: Vec<&str> = md.lines().take(40).collect();
    assert!(
        first
            .iter()
            .any(|l| l.starts_with(&format!("| {label} | 2 |"))),
        "{md}"
    );
}

#[test]
fn the_answer_says_not_resolved_where_the_findings_do() {
    // The same means, but rounds that disagree: no winner at 2 cores.
    let md = drifting_report([0.66, 0.76, 0.52]);
    let label = "seed preset, all-pairs, N = 60, 3 steps";
    let two = row(&md, label, 2);
    assert!(
        two.contains("| 2 | rayon-iter | ")
            && two.ends_with("| *not resolved* against rayon-chunks |"),
        "{md}"
    );
    assert!(!two.contains("**"), "{md}");
    assert_eq!(answer_agrees_with_findings(&md), 2);
}

#[test]
fn a_directory_without_trials_gets_no_answer_but_the_reason() {
    let (_tmp, dir) = scratch("results");
    std::fs::create_dir_all(&dir).unwrap();
    for f in ["meta.json", "summary.csv"] {
        std::fs::copy(fixture().join(f), dir.join(f)).unwrap();
    }
    let md = report_md(&[&dir], &dir);
    let section = answer(&md);
    // One row per group (four in the fixture), each withheld with the reason, no strategy.
    let rows: Vec<&str> = section
        .lines()
        .filter(|l| l.starts_with("| seed"))
        .collect();
    assert_eq!(rows.len(), 4, "{section}");
    for r in &rows {
        assert!(
            r.ends_with(
                "| — | — | — | — findings withheld: no trials.csv, so its statistics were not \
                 checked |"
            ),
            "{r}"
        );
    }
    // The banner that says why comes with the build line, before the answer.
    let banner = md.find("> ⚠ **Statistics not checked**").expect("banner");
    assert!(banner < md.find("## The answer").unwrap());
    // The fixture with its trials.csv is an older sweep, measured before rounds.
    let (_tmp2, out) = scratch("out");
    let md = report_md(&[&fixture()], &out);
    assert_eq!(
        answer(&md)
            .matches("— findings withheld: an older sweep, measured before rounds |")
            .count(),
        4,
        "{md}"
    );
}
