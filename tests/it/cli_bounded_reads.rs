//! Every file of a results, trace or output directory is read as a regular file within a cap
//! of its kind: a FIFO, a device or a link to one is refused at once with a clear message
//! (never a hang, never an allocation of gigabytes), and a file beyond its cap is refused
//! naming the cap. Each command runs under a bounded wait (`output_within_a_minute`).

use std::path::{Path, PathBuf};
use std::process::Output;

use crate::common::*;

/// Makes `path` a FIFO; false where `mkfifo` is missing (the test then has nothing to check).
fn mkfifo(path: &Path) -> bool {
    std::process::Command::new("mkfifo")
        .arg(path)
        .status()
        .is_ok_and(|s| s.success())
}

/// Replaces `path` with a symbolic link to `/dev/zero`.
fn dev_zero(path: &Path) {
    let _ = std::fs::remove_file(path);
    std::os::unix::fs::symlink("/dev/zero", path).unwrap();
}

/// Runs `args` within a minute.
fn bounded(args: &[&str]) -> Output {
    let mut cmd = bench_sph();
    cmd.args(args);
    output_within_a_minute(cmd)
}

/// Asserts a clean refusal (exit 1, no panic, no abort) whose message holds `needles`.
fn refused(o: &Output, needles: &[&str]) {
    assert_eq!(o.status.code(), Some(1), "{}", stderr(o));
    no_panic(o);
    assert_holds_all("the refusal", &stderr(o), needles);
}

#[test]
fn report_reading_dev_zero_as_summary_is_refused_at_once() {
    let (_tmp, dir) = scratch("r");
    swept(&dir, &["--no-plots"]);
    let summary = dir.join("summary.csv");
    dev_zero(&summary);
    let o = bounded(&["report", dir.to_str().unwrap()]);
    refused(
        &o,
        &[&format!(
            "'{}' is a character device (through a symbolic link), not a regular file",
            summary.display()
        )],
    );
}

#[test]
fn a_summary_larger_than_its_cap_is_refused_naming_the_cap() {
    let (_tmp, dir) = scratch("r");
    swept(&dir, &["--no-plots"]);
    let summary = dir.join("summary.csv");
    // Sparse: it takes no disk, but says 1 GiB and a byte.
    std::fs::File::create(&summary)
        .unwrap()
        .set_len((1 << 30) + 1)
        .unwrap();
    let o = bounded(&["report", dir.to_str().unwrap()]);
    refused(
        &o,
        &[&format!(
            "Error: '{}' is larger than 1 GiB, the most a summary.csv may be",
            summary.display()
        )],
    );
}

#[test]
fn report_and_resume_refuse_meta_json_linked_to_dev_zero_at_once() {
    let (_tmp, dir) = scratch("r");
    swept(&dir, &["--no-plots"]);
    let meta = dir.join("meta.json");
    dev_zero(&meta);
    let needle = format!("'{}' is a character device", meta.display());
    let d = dir.to_str().unwrap();
    refused(&bounded(&["report", d]), &[&needle]);
    refused(&bounded(&["sweep", "--resume", d]), &[&needle]);
}

#[test]
fn report_refuses_trials_as_a_fifo_at_once() {
    let (_tmp, dir) = scratch("r");
    swept(&dir, &["--no-plots"]);
    let trials = dir.join("trials.csv");
    std::fs::remove_file(&trials).unwrap();
    if !mkfifo(&trials) {
        return;
    }
    let o = bounded(&["report", dir.to_str().unwrap()]);
    refused(
        &o,
        &["trials.csv' is a FIFO (named pipe), not a regular file"],
    );
}

#[test]
fn a_trace_whose_meta_json_is_a_fifo_is_skipped_not_waited_on() {
    let (tmp, dir) = scratch("r");
    swept(&dir, &["--no-plots"]);
    let trace = dir.join("trace-seq");
    let o = run(&[
        "trace",
        "--strategy",
        "seq",
        "--n",
        "60",
        "--out",
        trace.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    std::fs::remove_file(trace.join("meta.json")).unwrap();
    if !mkfifo(&trace.join("meta.json")) {
        return;
    }
    let o = bounded(&[
        "report",
        dir.to_str().unwrap(),
        "--out",
        tmp.path().join("out").to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_holds_all(
        "the warning",
        &stderr(&o),
        &["skipping trace directory", "is a FIFO (named pipe)"],
    );
}

#[test]
fn a_record_linked_to_dev_zero_is_refused_at_once() {
    let (_tmp, dir) = scratch("t");
    std::fs::create_dir(&dir).unwrap();
    dev_zero(&dir.join("bench-sph-files.json"));
    let o = bounded(&[
        "trace",
        "--strategy",
        "seq",
        "--n",
        "60",
        "--out",
        dir.to_str().unwrap(),
    ]);
    refused(&o, &["bench-sph-files.json' is a character device"]);
    assert!(!dir.join("trace.json").exists());
}

/// Merges `shards` into `out` within a minute.
fn merge_within_a_minute(shards: &[PathBuf], out: &Path) -> Output {
    output_within_a_minute(merge_command(shards, out, &[]))
}

#[test]
fn merge_refuses_a_fifo_at_once() {
    let _alone = alone();
    let tmp = tempfile::tempdir().unwrap();
    let shards = two_shards(tmp.path());
    let trials = shards[0].join("trials.csv");
    std::fs::remove_file(&trials).unwrap();
    if !mkfifo(&trials) {
        return;
    }
    let out = tmp.path().join("merged");
    refused(
        &merge_within_a_minute(&shards, &out),
        &[&format!("'{}' is a FIFO (named pipe)", trials.display())],
    );
    assert!(!out.join("summary.csv").exists());
}

#[test]
fn merge_refuses_a_shard_file_linked_to_dev_zero_at_once() {
    let _alone = alone();
    let tmp = tempfile::tempdir().unwrap();
    let shards = two_shards(tmp.path());
    let out = tmp.path().join("merged");
    for name in ["trials.csv", "summary.csv", "meta.json"] {
        let path = shards[1].join(name);
        let kept = std::fs::read(&path).unwrap();
        dev_zero(&path);
        refused(
            &merge_within_a_minute(&shards, &out),
            &[&format!("'{}' is a character device", path.display())],
        );
        std::fs::remove_file(&path).unwrap();
        std::fs::write(&path, kept).unwrap();
    }
    assert!(!out.join("summary.csv").exists());
    let o = merge_within_a_minute(&shards, &out);
    assert!(o.status.success(), "{}", stderr(&o));
}

#[test]
fn merge_refuses_trials_larger_than_the_cap_naming_it() {
    let _alone = alone();
    let tmp = tempfile::tempdir().unwrap();
    let shards = two_shards(tmp.path());
    let trials = shards[0].join("trials.csv");
    std::fs::OpenOptions::new()
        .write(true)
        .open(&trials)
        .unwrap()
        .set_len((1 << 30) + 1)
        .unwrap();
    refused(
        &merge_within_a_minute(&shards, &tmp.path().join("merged")),
        &[&format!(
            "'{}' is larger than 1 GiB, the most a trials.csv may be",
            trials.display()
        )],
    );
}
