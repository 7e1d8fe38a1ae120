//! What a sweep measures beside its cells (`--pass-cost`, `--anchor`), driven through the
//! built binary: both files written and recorded, the report setting them beside the cells,
//! a failing anchor keeping the cells for `--resume`, and bad input refused before anything
//! runs. The anchor here is a shell script standing in for the plain loop's OpenMP build
//! (whose own state is checked in `plain_loop`): it prints the plain loop's JSON line.

use std::path::{Path, PathBuf};

use crate::common::{fails_with, run, stderr, stdout, tiny_fake_sweep, tiny_fake_sweep_into};

/// The checksum of `seq` on the tiny sweep's workload (N = 60, 3 steps, the default seed).
fn seq_checksum() -> String {
    let o = run(&["simulate", "--n", "60", "--steps", "3", "--json"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_str(stdout(&o).trim()).unwrap();
    v["checksum"].as_str().unwrap().to_owned()
}

/// Writes an anchor script into `dir` that ends in `checksum` and takes 1 s on one thread,
/// 0.5 s on two, or fails when `fails`.
fn anchor(dir: &Path, checksum: &str, fails: bool) -> PathBuf {
    let path = dir.join("anchor.sh");
    let body = if fails {
        "echo 'no OpenMP here' >&2\nexit 3\n".to_owned()
    } else {
        format!(
            "case \"$OMP_NUM_THREADS\" in 1) w=1.0 ;; 2) w=0.5 ;; *) exit 4 ;; esac\n\
             printf '{{\"n\":%s,\"steps\":%s,\"wall_s\":%s,\"checksum\":\"{checksum}\"}}\\n' \
             \"$1\" \"$2\" \"$w\"\n"
        )
    };
    std::fs::write(&path, format!("#!/bin/sh\n{body}")).unwrap();
    use std::os::unix::fs::PermissionsExt;
    std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o755)).unwrap();
    path
}

fn lines(path: &Path) -> Vec<String> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .map(str::to_owned)
        .collect()
}

#[test]
fn pass_costs_and_the_anchor_are_written_recorded_and_reported_beside_the_cells() {
    let tmp = tempfile::tempdir().unwrap();
    let script = anchor(tmp.path(), &seq_checksum(), false);
    let out = tmp.path().join("out");
    let o = tiny_fake_sweep_into(&out, &["--pass-cost", "--anchor", script.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stdout(&o).contains("OpenMP anchor, paired speedup: 2 threads 2.00×"));

    let costs = lines(&out.join("pass-cost.csv"));
    assert_eq!(
        costs[0],
        "strategy,cores,work_us,pass_us,pass_low_us,pass_high_us,beyond_work_us,oversubscribed"
    );
    let cells: Vec<(&str, &str)> = costs[1..]
        .iter()
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            (f[0], f[1])
        })
        .collect();
    // seq runs on the calling thread: one core only.
    assert_eq!(
        cells,
        [("seq", "1"), ("rayon-chunks", "1"), ("rayon-chunks", "2")]
    );

    // One run a thread count a round, 1 thread (the reference) among them, 3 rounds.
    let runs = lines(&out.join("anchor.csv"));
    assert_eq!(runs.len(), 1 + 2 * 3, "{runs:?}");
    for round in 1..=3 {
        let threads: Vec<&str> = runs[1..]
            .iter()
            .map(|l| l.split(',').collect::<Vec<_>>())
            .filter(|f| f[4] == round.to_string())
            .map(|f| f[3])
            .collect();
        assert!(threads.contains(&"1") && threads.contains(&"2"), "{runs:?}");
    }

    let record = std::fs::read_to_string(out.join("bench-sph-files.json")).unwrap();
    assert!(record.contains("\"pass-cost.csv\": \"sweep\""), "{record}");
    assert!(record.contains("\"anchor.csv\": \"sweep\""), "{record}");
    let report = std::fs::read_to_string(out.join("REPORT.md")).unwrap();
    assert!(report.contains("### Where the curves bend"), "{report}");
    assert!(report.contains("| rayon-chunks | 2 |"), "{report}");
    assert!(
        report.contains("| OpenMP plain loop | 2 | – | – | – | 2.00×"),
        "{report}"
    );
}

#[test]
fn an_anchor_of_another_state_is_not_set_beside_the_strategies() {
    let tmp = tempfile::tempdir().unwrap();
    let script = anchor(tmp.path(), "0123456789abcdef", false);
    let out = tmp.path().join("out");
    let o = tiny_fake_sweep_into(&out, &["--anchor", script.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stdout(&o).contains("did not compute seq's state"),
        "{}",
        stdout(&o)
    );
    let report = std::fs::read_to_string(out.join("REPORT.md")).unwrap();
    assert!(!report.contains("| OpenMP plain loop |"), "{report}");
    assert!(report.contains("did not compute this workload"), "{report}");
}

#[test]
fn a_failing_anchor_keeps_the_cells_and_resume_measures_it() {
    let tmp = tempfile::tempdir().unwrap();
    let script = anchor(tmp.path(), "", true);
    let out = tmp.path().join("out");
    let o = tiny_fake_sweep_into(&out, &["--anchor", script.to_str().unwrap(), "--no-plots"]);
    assert!(!o.status.success());
    let err = stderr(&o);
    assert!(err.contains("\nError: --anchor '"), "{err}");
    assert!(
        err.contains("no OpenMP here") && err.contains("--resume"),
        "{err}"
    );
    assert!(!out.join("anchor.csv").exists());
    let meta = std::fs::read_to_string(out.join("meta.json")).unwrap();
    assert!(meta.contains("\"status\": \"interrupted\""), "{meta}");
    let cells = lines(&out.join("summary.csv"));
    // The grid's 3 cells and the confirmation's.
    assert!(cells.len() > 3, "the cells are kept: {cells:?}");

    anchor(tmp.path(), &seq_checksum(), false);
    let o = run(&["sweep", "--resume", out.to_str().unwrap(), "--no-plots"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(lines(&out.join("anchor.csv")).len(), 1 + 2 * 3);
    assert_eq!(
        lines(&out.join("summary.csv")),
        cells,
        "no cell measured again"
    );
}

#[test]
fn bad_pass_cost_or_anchor_input_is_refused_before_anything_runs() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    let refused = |extra: &[&str], needles: &[&str]| {
        let args = [
            &tiny_fake_sweep()[..],
            &["--out", out.to_str().unwrap()],
            extra,
        ]
        .concat();
        fails_with(&args, needles);
        assert!(!out.exists(), "nothing written: {extra:?}");
    };
    let missing = tmp.path().join("missing");
    refused(
        &["--anchor", missing.to_str().unwrap()],
        &["Error: --anchor '", "no such program"],
    );
    let script = anchor(tmp.path(), "", false);
    let plain = tmp.path().join("plain.txt");
    std::fs::write(&plain, "not a program").unwrap();
    refused(
        &["--anchor", plain.to_str().unwrap()],
        &["Error: --anchor '", "not executable"],
    );
    refused(
        &["--anchor", script.to_str().unwrap(), "--neighbors", "grid"],
        &["Error: --anchor: the plain loop computes the seed preset with all-pairs"],
    );
    refused(
        &["--pass-cost", "--shard", "1/2"],
        &["Error: --shard 1/2 with --pass-cost or --anchor"],
    );
}

#[test]
fn a_pass_cost_file_the_sweep_did_not_measure_is_not_reported() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    let o = tiny_fake_sweep_into(&out, &["--no-plots"]);
    assert!(o.status.success(), "{}", stderr(&o));
    // Someone's own file of that name, well-formed: not the sweep's, so not read.
    std::fs::write(
        out.join("pass-cost.csv"),
        "strategy,cores,work_us,pass_us,pass_low_us,pass_high_us,beyond_work_us,oversubscribed\n\
         rayon-chunks,2,5.0,6.5,6.4,6.6,1.5,false\n",
    )
    .unwrap();
    let o = run(&["report", out.to_str().unwrap(), "--force"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let report = std::fs::read_to_string(out.join("REPORT.md")).unwrap();
    assert!(!report.contains("Where the curves bend"), "{report}");
}
