//! Helpers shared by the integration tests that drive the `bench-sph` binary: runs through
//! `assert_cmd` (whose failures show the command, its exit and both streams), with
//! `predicates` for what standard error must hold.

#![allow(dead_code)] // each test file uses its own subset

use std::collections::HashMap;
use std::path::Path;
use std::process::{Command, Output};

use assert_cmd::assert::Assert;
use predicates::prelude::*;
use predicates::str::contains;

/// A CSV row by column name.
pub type Row = HashMap<String, String>;

/// The built binary, ready for arguments (a std `Command`, so that a test may also spawn it).
pub fn bench_sph() -> Command {
    Command::new(env!("CARGO_BIN_EXE_bench-sph"))
}

/// Runs the binary with `args` to the end, whatever its outcome.
pub fn run(args: &[&str]) -> Output {
    bench_sph().args(args).output().expect("binary runs")
}

/// [`run`], in `dir`.
pub fn run_in(dir: &Path, args: &[&str]) -> Output {
    let mut cmd = bench_sph();
    cmd.args(args)
        .current_dir(dir)
        .output()
        .expect("binary runs")
}

/// Runs `cmd` to the end under `assert_cmd`.
pub fn assert(cmd: Command) -> Assert {
    assert_cmd::Command::from_std(cmd).assert()
}

/// Runs `args` in `dir` and expects success; returns standard output.
pub fn succeeds(dir: &Path, args: &[&str]) -> String {
    let mut cmd = bench_sph();
    cmd.args(args).current_dir(dir);
    text(&assert(cmd).success().get_output().stdout)
}

/// Runs `args` and expects a failure whose standard error holds every one of `needles`, and
/// no panic.
pub fn fails_with(args: &[&str], needles: &[&str]) -> Output {
    let mut cmd = bench_sph();
    cmd.args(args);
    expect_failure(cmd, needles)
}

/// [`fails_with`], run in `dir`.
pub fn fails_with_in(dir: &Path, args: &[&str], needles: &[&str]) -> Output {
    let mut cmd = bench_sph();
    cmd.args(args).current_dir(dir);
    expect_failure(cmd, needles)
}

/// Runs `cmd` and expects a failure whose standard error holds every one of `needles`, and
/// no panic.
pub fn expect_failure(cmd: Command, needles: &[&str]) -> Output {
    let mut failed = assert(cmd).failure();
    for &needle in needles {
        failed = failed.stderr(contains(needle));
    }
    let no_panic = contains("panicked").or(contains("RUST_BACKTRACE")).not();
    failed.stderr(no_panic).get_output().clone()
}

/// Bytes of an output stream as text.
pub fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

/// A run's standard output as text.
pub fn stdout(o: &Output) -> String {
    text(&o.stdout)
}

/// A run's standard error as text.
pub fn stderr(o: &Output) -> String {
    text(&o.stderr)
}

/// The names of the entries of `dir`, sorted.
pub fn names(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

/// The rows of a results CSV.
pub fn rows(path: &Path) -> Vec<Row> {
    let mut r = csv::Reader::from_path(path).unwrap();
    let header = r.headers().unwrap().clone();
    r.records()
        .map(|rec| {
            let rec = rec.unwrap();
            header
                .iter()
                .zip(rec.iter())
                .map(|(k, v)| (k.to_owned(), v.to_owned()))
                .collect()
        })
        .collect()
}

/// Fails the test if the command panicked.
pub fn no_panic(o: &Output) {
    let err = text(&o.stderr);
    assert!(!err.contains("panicked"), "panicked:\n{err}");
}
