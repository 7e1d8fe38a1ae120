//! `bench-sph report` given hostile input: impossible rows, the same cells twice, a foreign
//! output directory, stale charts and a partial study. Every case ends in a clear message;
//! nothing impossible becomes a number.

use std::path::Path;
use std::process::Output;

use crate::common::{
    assert_file_holds, fake_sweep, line_containing, read_json, run, scratch, sweep_into, text,
};

/// A small finished sweep under fake times: seq, rayon-chunks and rayon-iter at 1 and 2 cores,
/// N = `n` (a list).
fn sweep_of(n: &str, dir: &Path, extra: &[&str]) -> Output {
    let mut args = fake_sweep(
        "seq,rayon-chunks,rayon-iter",
        "1.0,1.1,0.9,0.5,0.55,0.6,0.7,0.8,0.75",
    );
    let at = args.iter().position(|a| *a == "--n").unwrap();
    args[at + 1] = n;
    args.extend(["--no-plots", "--out", dir.to_str().unwrap()]);
    args.extend(extra);
    run(&args)
}

/// [`sweep_of`] N = 60.
fn sweep(dir: &Path, extra: &[&str]) -> Output {
    sweep_of("60", dir, extra)
}

/// Runs `report` on `dirs` into `out`, then `extra`.
fn report_into(dirs: &[&Path], out: &Path, extra: &[&str]) -> Output {
    let mut args = vec!["report"];
    args.extend(dirs.iter().map(|d| d.to_str().unwrap()));
    args.extend(["--out", out.to_str().unwrap()]);
    args.extend(extra);
    run(&args)
}

/// Asserts that the report `o` into `out` failed, naming every one of `needles`, and wrote no
/// REPORT.md there; returns its standard error.
fn refused(o: &Output, out: &Path, needles: &[&str]) -> String {
    assert!(!o.status.success());
    let err = text(&o.stderr);
    assert!(needles.iter().all(|n| err.contains(n)), "{err}");
    assert!(!out.join("REPORT.md").exists());
    err
}

fn finished(dir: &Path) {
    let o = sweep(dir, &[]);
    assert!(o.status.success(), "{}", text(&o.stderr));
}

/// Replaces field `column` of the summary row of `strategy` at `cores` with `value`.
fn edit_summary(dir: &Path, strategy: &str, cores: &str, column: &str, value: &str) {
    let path = dir.join("summary.csv");
    let body = std::fs::read_to_string(&path).unwrap();
    let mut lines: Vec<String> = body.lines().map(str::to_owned).collect();
    let header: Vec<&str> = lines[0].split(',').collect();
    let at = header.iter().position(|h| *h == column).unwrap();
    let line = lines
        .iter_mut()
        .find(|l| {
            let f: Vec<&str> = l.split(',').collect();
            f[0] == strategy && f[5] == cores
        })
        .unwrap();
    let mut fields: Vec<String> = line.split(',').map(str::to_owned).collect();
    fields[at] = value.to_owned();
    *line = fields.join(",");
    std::fs::write(&path, lines.join("\n") + "\n").unwrap();
}

#[test]
fn impossible_rows_are_left_out_with_a_listed_warning() {
    let tmp = tempfile::tempdir().unwrap();
    for (case, (column, value, reason)) in [
        ("mean_s", "NaN", "mean_s = NaN"),
        ("mean_s", "-0.5", "mean_s = -0.5"),
        ("min_s", "0", "min_s = 0"),
        ("speedup", "inf", "speedup = inf"),
        ("mean_s", "0.7501", "disagrees with its trial rows"),
        ("cores", "1000000000", "cores must be between 1 and 1024"),
    ]
    .into_iter()
    .enumerate()
    {
        let dir = tmp.path().join(format!("case{case}"));
        finished(&dir);
        edit_summary(&dir, "rayon-iter", "2", column, value);
        let o = run(&["report", dir.to_str().unwrap()]);
        assert!(o.status.success(), "{}", text(&o.stderr));
        let err = text(&o.stderr);
        assert!(
            err.contains("row left out of the report") && err.contains(reason),
            "{column}={value}: {err}"
        );
        let md = std::fs::read_to_string(dir.join("REPORT.md")).unwrap();
        assert!(md.contains("1 row left out"), "{md}");
        let tables: Vec<&str> = md.lines().filter(|l| l.starts_with('|')).collect();
        assert!(
            !tables
                .iter()
                .any(|l| l.contains("-0.5") || l.contains("NaN")),
            "{md}"
        );
    }
}

#[test]
fn a_line_cut_off_by_a_kill_is_left_out_with_a_warning_not_an_error() {
    let (_tmp, dir) = scratch("r");
    finished(&dir);
    let mut trials = std::fs::read_to_string(dir.join("trials.csv")).unwrap();
    trials.push_str("rayon-iter,all-pairs,seed,60,3,2,,,4,0.");
    std::fs::write(dir.join("trials.csv"), trials).unwrap();
    let o = run(&["report", dir.to_str().unwrap()]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert!(
        text(&o.stderr).contains("not a bench-sph trial row"),
        "{}",
        text(&o.stderr)
    );
    let md = std::fs::read_to_string(dir.join("REPORT.md")).unwrap();
    assert!(md.contains("1 row left out"), "{md}");
}

#[test]
fn the_same_directory_twice_or_the_same_cells_in_two_directories_are_refused() {
    let (tmp, a) = scratch("a");
    finished(&a);
    let o = run(&["report", a.to_str().unwrap(), a.to_str().unwrap()]);
    assert!(!o.status.success());
    assert!(
        text(&o.stderr).contains("is given twice"),
        "{}",
        text(&o.stderr)
    );

    let b = tmp.path().join("b");
    finished(&b);
    let out = tmp.path().join("out");
    let o = report_into(&[&a, &b], &out, &[]);
    let err = refused(&o, &out, &["is in both"]);
    assert!(err.starts_with("Error: the cell"), "{err}");
}

#[test]
fn an_out_directory_with_foreign_files_is_refused_unless_force_which_keeps_them() {
    let (tmp, dir) = scratch("r");
    finished(&dir);
    let out = tmp.path().join("out");
    std::fs::create_dir(&out).unwrap();
    std::fs::write(out.join("dambreak.gif"), "mine").unwrap();
    let o = report_into(&[&dir], &out, &[]);
    refused(&o, &out, &["'dambreak.gif'", "--force"]);

    let o = report_into(&[&dir], &out, &["--force"]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert!(out.join("REPORT.md").is_file());
    assert_file_holds(&out.join("dambreak.gif"), "mine");
}

#[test]
fn charts_of_an_earlier_report_that_are_not_drawn_again_are_removed() {
    let (_tmp, dir) = scratch("r");
    finished(&dir);
    // A chart of a group the data no longer holds: a chart an earlier report drew and
    // recorded (here a copy of a real chart, entered in the record as the report's).
    assert!(run(&["report", dir.to_str().unwrap()]).status.success());
    let stale = dir.join("seed-all-pairs-n999-s3-4-speedup.png");
    std::fs::copy(dir.join("seed-all-pairs-n60-s3-4-speedup.png"), &stale).unwrap();
    let record = dir.join("bench-sph-files.json");
    let mut entries = read_json(&record);
    entries["files"]["seed-all-pairs-n999-s3-4-speedup.png"] = "report".into();
    std::fs::write(&record, entries.to_string()).unwrap();
    // A user's files that merely look like the report's by name are not its own.
    std::fs::write(dir.join("seed-holiday.png"), "a photo").unwrap();
    let o = run(&["report", dir.to_str().unwrap()]);
    assert!(!o.status.success());
    assert!(
        text(&o.stderr).contains("'seed-holiday.png'"),
        "{}",
        text(&o.stderr)
    );
    let o = run(&["report", dir.to_str().unwrap(), "--force"]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert!(!stale.exists(), "the stale chart stayed");
    assert_file_holds(&dir.join("seed-holiday.png"), "a photo");
    assert!(dir.join("seed-all-pairs-n60-s3-4-speedup.png").is_file());
    // No temporary file is left behind.
    for e in std::fs::read_dir(&dir).unwrap() {
        let name = e.unwrap().file_name().to_string_lossy().into_owned();
        assert!(!name.ends_with(".tmp"), "{name}");
    }
}

#[test]
fn a_partial_study_says_so_at_the_top() {
    let (_tmp, dir) = scratch("r");
    // Two groups; stopped after the first one's 15 grid and 15 confirmation runs.
    let o = sweep_of("60,120", &dir, &["--stop-after-runs", "30"]);
    assert!(!o.status.success());
    let o = run(&["report", dir.to_str().unwrap()]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let md = std::fs::read_to_string(dir.join("REPORT.md")).unwrap();
    let banner = line_containing(&md, "Partial study");
    assert!(
        banner.contains("is interrupted — 5 of 10 planned cells measured")
            && banner.contains("--resume"),
        "{banner}"
    );
    let first_section = md.find("## ").unwrap();
    assert!(md.find("Partial study").unwrap() < first_section);
}

#[test]
fn a_one_cell_report_reads_naturally() {
    let (_tmp, dir) = scratch("r");
    let o = sweep_into(
        &dir,
        "--n 60 --steps 3 --trials 2 --strategies seq --cores 1 --fake-timings 1.0,1.1",
    );
    assert!(o.status.success(), "{}", text(&o.stderr));
    let md = std::fs::read_to_string(dir.join("REPORT.md")).unwrap();
    assert!(md.contains(": 1 cell in 1 group."), "{md}");
    assert!(
        md.contains(
            "Charts 3–5 (against cores) are not drawn: no parallel strategy has a usable cell."
        ),
        "{md}"
    );
    assert!(
        !md.contains("1 cells") && !md.contains("only no core"),
        "{md}"
    );
}
