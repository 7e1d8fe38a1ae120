//! Every numeric option has a documented range (`harness/src/limits.rs`), checked when the command
//! line is parsed: a value beyond it is a clear error with a non-zero exit, before any thread
//! is started or any memory allocated — never an abort, a panic or a hang.

use crate::common::fails_with_in;

/// Runs `args` in an empty directory and expects a failure naming `needle`, with nothing
/// written.
fn refused(args: &[&str], needle: &str) {
    let tmp = tempfile::tempdir().unwrap();
    fails_with_in(tmp.path(), args, &[needle]);
    assert_eq!(
        std::fs::read_dir(tmp.path()).unwrap().count(),
        0,
        "{args:?} wrote something"
    );
}

#[test]
fn thread_counts_beyond_the_documented_maximum_are_refused_by_every_command() {
    for command in ["simulate", "trace", "render"] {
        for strategy in ["crossbeam-pool", "std-static", "rayon-chunks"] {
            refused(
                &[command, "--strategy", strategy, "--cores", "20000"],
                "cores must be between 1 and 1024, not 20000",
            );
        }
    }
    refused(
        &["simulate", "--strategy", "std-static", "--cores", "1000000"],
        "cores must be between 1 and 1024",
    );
    refused(
        &["sweep", "--cores", "18446744073709551615"],
        "goes above 1024, the most cores allowed",
    );
    refused(&["sweep", "--cores", "1..100000"], "goes above 1024");
}

#[test]
fn particle_step_and_trial_counts_beyond_their_ranges_are_refused() {
    refused(
        &["simulate", "--n", "18446744073709551615"],
        "particles must be between 1 and 100000000",
    );
    refused(&["sweep", "--n", "1000000000"], "goes above 100000000");
    refused(&["simulate", "--steps", "0"], "must be between 1 and");
    refused(
        &["simulate", "--steps", "1000000001"],
        "between 1 and 1000000000",
    );
    refused(&["sweep", "--trials", "1001"], "between 1 and 1000");
    refused(&["sweep", "--warmup", "1001"], "between 0 and 1000");
    refused(&["sweep", "--chunks", "99999999999"], "goes above 10000000");
}

#[test]
fn a_sweep_whose_lists_multiply_beyond_the_cell_limit_is_refused() {
    refused(
        &[
            "sweep",
            "--cores",
            "1..1024",
            "--chunks",
            "1..99991:10",
            "--n",
            "100..1000000:100",
        ],
        "would have more than 1000000 cells",
    );
}
