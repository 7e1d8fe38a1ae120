//! `--pin none|compact|spread` end to end: every strategy pinned gives the unpinned `seq`
//! checksum on `simulate`; `trace` records the placement; `sweep --pin` makes it a cell
//! dimension with `pin` and `smt` columns; `meta.json` carries the machine's topology; a bad
//! placement name is a clear error. (This 2-core machine has no SMT: the SMT cases are tested
//! on injected topologies in `harness/src/topology`.)

use crate::common::*;

fn simulate_json(extra: &[&str]) -> serde_json::Value {
    let mut args = vec!["simulate", "--n", "200", "--steps", "10", "--json"];
    args.extend(extra);
    let o = run(&args);
    assert!(o.status.success(), "{args:?}: {}", stderr(&o));
    serde_json::from_str(stdout(&o).trim()).expect("one JSON object")
}

#[test]
fn every_strategy_pinned_compact_or_spread_ends_with_the_unpinned_seq_checksum() {
    let reference = simulate_json(&["--neighbors", "grid"]);
    assert_eq!(reference["pin"], "none");
    for pin in ["compact", "spread"] {
        for strategy in [
            "seq",
            "rayon-iter",
            "rayon-spawn",
            "rayon-chunks",
            "crossbeam-pool",
            "std-static",
        ] {
            let v = simulate_json(&[
                "--neighbors",
                "grid",
                "--strategy",
                strategy,
                "--cores",
                "2",
                "--pin",
                pin,
            ]);
            assert_eq!(v["pin"], pin);
            assert_eq!(
                v["checksum"], reference["checksum"],
                "{strategy} --pin {pin}"
            );
        }
    }
}

#[test]
fn an_unknown_placement_is_refused_naming_the_three() {
    fails_with(
        &["simulate", "--pin", "scatter"],
        &["invalid value 'scatter'", "none", "compact", "spread"],
    );
    fails_with(
        &["sweep", "--pin", "none,scatter", "--n", "60"],
        &["invalid value 'scatter'"],
    );
}

#[test]
fn a_trace_records_its_placement() {
    let (_tmp, dir) = scratch("t");
    let out = dir.to_str().unwrap();
    let o = run(&[
        "trace",
        "--strategy",
        "rayon-chunks",
        "--cores",
        "2",
        "--n",
        "200",
        "--steps",
        "2",
        "--pin",
        "spread",
        "--out",
        out,
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let meta = read_json(&dir.join("meta.json"));
    assert_eq!(meta["pin"], "spread");
}

#[test]
fn a_sweep_over_placements_has_one_cell_per_pin_and_marks_smt_from_the_recorded_topology() {
    let (_tmp, dir) = scratch("s");
    let mut args = fake_sweep("rayon-chunks,std-static", "1");
    args.extend([
        "--pin",
        "spread,none",
        "--no-plots",
        "--out",
        dir.to_str().unwrap(),
    ]);
    let o = run(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stdout(&o).contains("placements: none, spread"),
        "{}",
        stdout(&o)
    );

    // The grid phase; the confirmation rounds measure some of its cells again, pins kept.
    let all = rows(&dir.join("summary.csv"));
    let summary: Vec<_> = all
        .iter()
        .filter(|r| r["phase"] == "grid")
        .cloned()
        .collect();
    assert!(
        all.iter()
            .any(|r| r["phase"] == "confirm" && r["pin"] == "spread")
    );
    // seq once (unpinned); rayon-chunks 2 cores × 1 chunks × 2 pins; std-static 2 × 2.
    assert_eq!(summary.len(), 1 + 4 + 4);
    assert_eq!(summary[0]["strategy"], "seq");
    assert_eq!(summary[0]["pin"], "none");
    let pins = |p: &str| summary.iter().filter(|r| r["pin"] == p).count();
    assert_eq!((pins("none"), pins("spread")), (5, 4));
    let trials = rows(&dir.join("trials.csv"));
    assert_eq!(
        trials
            .iter()
            .filter(|r| r["pin"] == "spread" && r["phase"] == "grid")
            .count(),
        4 * 3
    );

    let meta = read_json(&dir.join("meta.json"));
    assert_eq!(meta["params"]["pin"], serde_json::json!(["none", "spread"]));
    let topology = &meta["machine"]["topology"];
    let logical = topology["logical_cpus"].as_u64().unwrap();
    assert!(logical >= 1, "{topology}");
    eprintln!("this machine's topology: {topology}");
    // smt = more threads than physical cores, no more than the logical CPUs.
    match topology["physical_cores"].as_u64() {
        Some(physical) => {
            for r in &summary {
                let cores: u64 = r["cores"].parse().unwrap();
                let smt = physical < cores && cores <= logical;
                assert_eq!(r["smt"], smt.to_string(), "{r:?}");
            }
        }
        None => assert!(summary.iter().all(|r| r["smt"].is_empty())),
    }
}
