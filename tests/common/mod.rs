//! Helpers shared by the integration tests that drive the `bench-sph` binary.

#![allow(dead_code)] // each test file uses its own subset

use std::collections::HashMap;
use std::path::Path;
use std::process::{Command, Output};

/// A CSV row by column name.
pub type Row = HashMap<String, String>;

/// The built binary, ready for arguments.
pub fn bench_sph() -> Command {
    Command::new(env!("CARGO_BIN_EXE_bench-sph"))
}

/// Runs the binary with `args` to the end.
pub fn run(args: &[&str]) -> Output {
    bench_sph().args(args).output().expect("binary runs")
}

/// Bytes of an output stream as text.
pub fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
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
