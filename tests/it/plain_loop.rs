//! The plain C++ loop (`benches/plain-loop/mueller.cpp`): the reference of the speed figures
//! and, built with `-fopenmp`, the OpenMP team the strategies are measured against. Both must
//! end in bench-sph's state, whatever the number of threads. Where no C++ compiler with
//! OpenMP is installed (`$CXX`, default `g++`), the test says so on stderr and checks nothing.

use std::path::Path;
use std::process::Command;

use crate::common::{run, stderr, stdout};

/// The checksum a JSON line (the plain loop's or `simulate --json`'s) reports.
fn checksum_of(json: &str) -> String {
    let v: serde_json::Value = serde_json::from_str(json.trim()).unwrap();
    v["checksum"].as_str().unwrap().to_owned()
}

#[test]
fn the_plain_loop_ends_in_bench_sphs_state_serial_and_on_every_openmp_team() {
    let cxx = std::env::var("CXX").unwrap_or_else(|_| "g++".to_owned());
    let source = Path::new(env!("CARGO_MANIFEST_DIR")).join("benches/plain-loop/mueller.cpp");
    let dir = tempfile::tempdir().unwrap();
    let build = |name: &str, extra: &[&str]| -> Option<std::path::PathBuf> {
        let exe = dir.path().join(name);
        let built = Command::new(&cxx)
            .args(["-O2", "-ffp-contract=off", "-std=c++17"])
            .args(extra)
            .arg("-o")
            .arg(&exe)
            .arg(&source)
            .output()
            .ok()?;
        built.status.success().then_some(exe)
    };
    let (Some(serial), Some(team)) = (build("mueller", &[]), build("mueller-omp", &["-fopenmp"]))
    else {
        eprintln!("note: no C++ compiler with OpenMP ('{cxx}'): the plain loop was not checked");
        return;
    };
    // 200 steps: the dam has begun to fall, so every pass's order of operations shows in the
    // bits (in the first tens of steps a change of grouping in the density need not).
    let (n, steps) = ("300", "200");
    let o = run(&[
        "simulate",
        "--n",
        n,
        "--steps",
        steps,
        "--strategy",
        "seq",
        "--json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let expected = checksum_of(&stdout(&o));
    let plain = |exe: &Path, threads: &str| -> String {
        let o = Command::new(exe)
            .args([n, steps])
            .env("OMP_NUM_THREADS", threads)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        checksum_of(&String::from_utf8_lossy(&o.stdout))
    };
    assert_eq!(plain(&serial, "1"), expected, "the serial plain loop");
    for threads in ["1", "2", "3"] {
        assert_eq!(
            plain(&team, threads),
            expected,
            "OpenMP on {threads} threads"
        );
    }
}
