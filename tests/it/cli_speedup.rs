//! `bench-sph speedup` driven through the built binary: a strategy and seq stepped in turn
//! end with the bits of a plain run, the figures hang together, and bad input is an error.

use crate::common::{DIVERGING_INIT, fails_with, run, stderr, stdout};

fn json(args: &[&str]) -> serde_json::Value {
    let o = run(args);
    assert!(o.status.success(), "{}", stderr(&o));
    serde_json::from_str(stdout(&o).trim()).expect("one JSON object")
}

#[test]
fn both_copies_end_with_the_plain_runs_bits_and_the_figures_agree() {
    let scene = ["--n", "120", "--steps", "12", "--neighbors", "grid"];
    let plain = json(&[&["simulate", "--json"], &scene[..]].concat());
    for strategy in ["crossbeam-pool", "rayon-chunks", "std-static"] {
        let args = [
            &["speedup", "--json", "--strategy", strategy, "--cores", "2"],
            &scene[..],
        ]
        .concat();
        let v = json(&args);
        assert_eq!(v["checksum"], plain["checksum"], "{strategy}");
        assert_eq!(
            (v["n"].as_u64(), v["steps"].as_u64()),
            (Some(120), Some(12))
        );
        assert_eq!(v["cores"], 2);
        let (seq, par) = (
            v["seq_s"].as_f64().unwrap(),
            v["strategy_s"].as_f64().unwrap(),
        );
        let speedup = v["speedup"].as_f64().unwrap();
        assert!(seq > 0.0 && par > 0.0);
        assert!((speedup - seq / par).abs() <= 1e-9 * speedup, "{v}");
        assert!((v["efficiency"].as_f64().unwrap() - speedup / 2.0).abs() <= 1e-9);
        let s = &v["step_speedup"];
        let q: Vec<f64> = ["min", "q1", "median", "q3", "max"]
            .iter()
            .map(|k| s[k].as_f64().unwrap())
            .collect();
        assert!(q.windows(2).all(|w| w[0] <= w[1]) && q[0] > 0.0, "{s}");
        let hardware = std::thread::available_parallelism().map_or(1, |n| n.get());
        assert_eq!(v["oversubscribed"], hardware < 2);
    }
}

#[test]
fn text_output_names_both_sides_and_the_spread() {
    let o = run(&[
        "speedup",
        "--strategy",
        "crossbeam-pool",
        "--cores",
        "2",
        "--n",
        "60",
        "--steps",
        "4",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let out = stdout(&o);
    assert!(
        out.contains("crossbeam-pool (cores 2, chunks 10) against seq"),
        "{out}"
    );
    assert!(out.contains("speedup step by step: median"), "{out}");
    assert!(out.contains("(both)"), "{out}");
}

#[test]
fn more_threads_than_the_machine_has_are_flagged() {
    let hardware = std::thread::available_parallelism().map_or(1, |n| n.get());
    let cores = (hardware + 1).to_string();
    let o = run(&[
        "speedup",
        "--json",
        "--strategy",
        "crossbeam-pool",
        "--cores",
        &cores,
        "--n",
        "40",
        "--steps",
        "2",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_str(stdout(&o).trim()).unwrap();
    assert_eq!(v["oversubscribed"], true);
    assert!(stderr(&o).contains("(oversubscribed)"), "{}", stderr(&o));
}

#[test]
fn bad_input_is_a_clear_error() {
    fails_with(&["speedup", "--n", "40"], &["--strategy"]);
    fails_with(
        &["speedup", "--strategy", "nope", "--n", "40"],
        &["unknown strategy 'nope'"],
    );
    fails_with(
        &["speedup", "--strategy", "rayon-chunks", "--steps", "0"],
        &["--steps"],
    );
    fails_with(
        &["speedup", "--strategy", "rayon-chunks", "--order", "cell"],
        &["Error: --order cell needs --neighbors grid"],
    );
    let dir = tempfile::tempdir().unwrap();
    let init = dir.path().join("boom.csv");
    std::fs::write(&init, DIVERGING_INIT).unwrap();
    fails_with(
        &[
            "speedup",
            "--strategy",
            "crossbeam-pool",
            "--init",
            init.to_str().unwrap(),
        ],
        &["Error: the seq copy: ", "diverged at step 1"],
    );
}
