//! `bench-sph validate` driven through the built binary: at resolution 20 every verdict
//! passes, the two CSVs hold a sample every 0.01 s from 0 to the end (T ≥ 3.4), the chart is
//! a PNG and `--json` parses with every verdict passing; crossbeam-pool on 2 cores writes the
//! same bytes as seq; a failed verdict exits non-zero after writing its files; a directory
//! holding a file validate did not write is refused; bad input is an error, never a panic. No
//! test asserts a duration.

use std::path::Path;

use serde_json::Value;

use crate::common::{
    assert_holds_all, fails_with, names, no_panic, run, scratch, stderr, stdout, succeeds,
};

/// The t_s column of a validation CSV whose header must be `header`.
fn times(path: &Path, header: &str) -> Vec<f64> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some(header), "{}", path.display());
    lines
        .map(|l| {
            let cells: Vec<f64> = l.split(',').map(|c| c.parse().unwrap()).collect();
            assert_eq!(cells.len(), 3, "{l}");
            assert!(cells.iter().all(|c| c.is_finite()), "{l}");
            cells[0]
        })
        .collect()
}

fn assert_sampled_every_hundredth_to_the_end(path: &Path, header: &str) {
    let t = times(path, header);
    assert_eq!(t[0], 0.0);
    let last = *t.last().unwrap();
    assert!(
        last >= 0.767,
        "the run ends at T >= 3.4, t = 0.768 s: {last}"
    );
    for (k, &s) in t[..t.len() - 1].iter().enumerate() {
        let due = k as f64 * 0.01;
        assert!(s >= due && s < due + 0.001, "row {k}: t_s {s}");
    }
    assert!(t.windows(2).all(|w| w[1] > w[0]), "{t:?}");
}

#[test]
fn validate_at_resolution_20_passes_every_verdict_and_crossbeam_pool_writes_the_same_bytes() {
    let (tmp, seq_dir) = scratch("seq");
    let cwd = tmp.path();
    let out = seq_dir.to_str().unwrap();
    let text = succeeds(cwd, &["validate", "--resolution", "20", "--out", out]);
    let verdicts: Vec<&str> = text
        .lines()
        .filter(|l| l.starts_with("PASS ") || l.starts_with("FAIL "))
        .collect();
    assert_eq!(verdicts.len(), 3, "{text}");
    assert!(verdicts.iter().all(|l| l.starts_with("PASS ")), "{text}");
    assert!(text.contains("shifted right by T = 0.175"), "{text}");
    assert_eq!(
        names(&seq_dir),
        ["column_height.csv", "surge_front.csv", "validation.png"]
    );
    assert_sampled_every_hundredth_to_the_end(&seq_dir.join("surge_front.csv"), "t_s,T,Z");
    assert_sampled_every_hundredth_to_the_end(&seq_dir.join("column_height.csv"), "t_s,tau,H");
    let png = std::fs::read(seq_dir.join("validation.png")).unwrap();
    assert_eq!(png[..8], *b"\x89PNG\r\n\x1a\n");

    let pool_dir = cwd.join("pool");
    let json = succeeds(
        cwd,
        &[
            "validate",
            "--resolution",
            "20",
            "--out",
            pool_dir.to_str().unwrap(),
            "--json",
            "--strategy",
            "crossbeam-pool",
            "--cores",
            "2",
        ],
    );
    let v: Value = serde_json::from_str(&json).unwrap_or_else(|e| panic!("{e}: {json}"));
    assert_eq!(v["resolution"], 20);
    assert_eq!(v["fluid_particles"], 800);
    assert_eq!(v["strategy"], "crossbeam-pool");
    assert_eq!(v["passed"], true);
    let verdicts = v["verdicts"].as_array().unwrap();
    assert_eq!(verdicts.len(), 3);
    for verdict in verdicts {
        assert_eq!(verdict["pass"], true, "{verdict}");
        assert!(verdict["measured"].as_f64().unwrap() <= verdict["tolerance"].as_f64().unwrap());
    }
    assert_eq!(v["surge_front"].as_array().unwrap().len(), 15);
    assert_eq!(v["column_height"].as_array().unwrap().len(), 17);
    for name in ["surge_front.csv", "column_height.csv"] {
        let seq = std::fs::read(seq_dir.join(name)).unwrap();
        let pool = std::fs::read(pool_dir.join(name)).unwrap();
        assert!(seq == pool, "{name}: crossbeam-pool differs from seq");
    }
}

#[test]
fn an_out_directory_holding_a_foreign_file_is_refused_without_force() {
    let (_tmp, dir) = scratch("out");
    std::fs::create_dir(&dir).unwrap();
    std::fs::write(dir.join("notes.txt"), "mine").unwrap();
    let out = dir.to_str().unwrap();
    fails_with(
        &["validate", "--resolution", "4", "--out", out],
        &[
            "Error: --out",
            "'notes.txt'",
            "bench-sph validate did not write",
            "--force",
        ],
    );
    assert_eq!(names(&dir), ["notes.txt"]);
    assert_eq!(
        std::fs::read_to_string(dir.join("notes.txt")).unwrap(),
        "mine"
    );
}

#[test]
fn a_resolution_outside_4_to_400_is_refused_without_a_panic() {
    let o = fails_with(&["validate", "--resolution", "3"], &["--resolution"]);
    assert!(stdout(&o).is_empty());
    fails_with(&["validate", "--resolution", "x"], &["--resolution"]);
}

#[test]
fn a_failing_verdict_exits_non_zero_after_writing_its_files() {
    let (_tmp, out) = scratch("coarse");
    let o = run(&[
        "validate",
        "--resolution",
        "4",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(!o.status.success());
    assert_holds_all("stderr", &stderr(&o), &["Error: validation failed"]);
    assert_holds_all("stdout", &stdout(&o), &["FAIL"]);
    no_panic(&o);
    for file in ["surge_front.csv", "column_height.csv", "validation.png"] {
        assert!(out.join(file).is_file(), "{file} was written");
    }
}
