//! `bench-sph overhead` driven through the built binary: every cell asked for is measured,
//! no pass is faster than its work, and bad input is an error.

use crate::common::{fails_with, run, stderr, stdout};

#[test]
fn every_cell_asked_for_is_measured_and_no_pass_beats_its_work() {
    let o = run(&[
        "overhead",
        "--strategies",
        "seq,team,rayon-chunks",
        "--cores",
        "1..2",
        "--work-us",
        "20",
        "--passes",
        "20",
        "--rounds",
        "3",
        "--json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_str(stdout(&o).trim()).expect("one JSON object");
    let cells: Vec<(String, u64)> = v["cells"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| {
            (
                c["strategy"].as_str().unwrap().to_owned(),
                c["cores"].as_u64().unwrap(),
            )
        })
        .collect();
    // seq runs every pass on the calling thread: measured at one core only.
    let expected = [
        ("seq", 1),
        ("team", 1),
        ("team", 2),
        ("rayon-chunks", 1),
        ("rayon-chunks", 2),
    ];
    let expected: Vec<(String, u64)> = expected.iter().map(|&(s, c)| (s.to_owned(), c)).collect();
    assert_eq!(cells, expected);
    let hardware = std::thread::available_parallelism().map_or(1, |n| n.get()) as u64;
    for c in v["cells"].as_array().unwrap() {
        let (pass, low, high) = (
            c["pass_us"].as_f64().unwrap(),
            c["pass_low_us"].as_f64().unwrap(),
            c["pass_high_us"].as_f64().unwrap(),
        );
        // Every thread's chunk keeps it busy for 20 µs: no pass ends sooner.
        assert!(pass >= 20.0 && low <= pass && pass <= high, "{c}");
        assert!((c["beyond_work_us"].as_f64().unwrap() - (pass - 20.0)).abs() < 1e-9);
        assert_eq!(c["oversubscribed"], c["cores"].as_u64().unwrap() > hardware);
    }
    assert_eq!(
        (v["work_us"].as_u64(), v["rounds"].as_u64()),
        (Some(20), Some(3))
    );
}

#[test]
fn bad_numbers_are_errors_naming_their_range() {
    for (flag, value, says) in [
        ("--rounds", "2", "between 3 and 100"),
        ("--work-us", "1001", "between 0 and 1000"),
        ("--passes", "0", "between 1 and 100000"),
        ("--cores", "0", "--cores"),
        ("--strategies", "turbo", "turbo"),
    ] {
        fails_with(&["overhead", flag, value], &[says]);
    }
}
