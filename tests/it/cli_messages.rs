//! Messages that say what happened and what to do, and exit codes that agree across commands
//! (issue 40's unclear-message cases that are not about merge, ownership or locks).

use std::fs::File;
use std::process::Stdio;

use crate::common::{bench_sph, fails_with, fake_sweep, run, scratch, stderr};

/// Runs `args` with standard output on `/dev/full` (every write fails: no space left).
fn to_a_full_device(args: &[&str]) -> std::process::Output {
    let full = File::options().write(true).open("/dev/full").unwrap();
    bench_sph()
        .args(args)
        .stdout(Stdio::from(full))
        .output()
        .unwrap()
}

#[test]
fn seed_is_refused_with_wcsph_where_nothing_is_jittered() {
    fails_with(
        &[
            "simulate",
            "--preset",
            "wcsph",
            "--resolution",
            "8",
            "--steps",
            "1",
            "--seed",
            "7",
        ],
        &[
            "Error: --seed has nothing to seed with --preset wcsph",
            "drop --seed",
        ],
    );
    // Without --seed the same run works: the refusal is about the flag, not the preset.
    let o = run(&[
        "simulate",
        "--preset",
        "wcsph",
        "--resolution",
        "8",
        "--steps",
        "1",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
}

#[test]
fn seed_is_refused_with_init_where_the_file_places_every_particle() {
    let (_tmp, dir) = scratch("i");
    std::fs::create_dir_all(&dir).unwrap();
    let init = dir.join("init.csv");
    std::fs::write(&init, "x,y\n0.5,0.5\n0.6,0.5\n").unwrap();
    let path = init.to_str().unwrap();
    fails_with(
        &["simulate", "--init", path, "--steps", "1", "--seed", "7"],
        &["Error: --seed has nothing to seed with --init", "init.csv"],
    );
    let o = run(&["simulate", "--init", path, "--steps", "1"]);
    assert!(o.status.success(), "{}", stderr(&o));
}

#[test]
fn an_empty_name_in_a_list_is_named_as_one_with_the_names_allowed() {
    let o = fails_with(
        &["sweep", "--pin", "spread,,", "--quick", "--no-plots"],
        &["--pin has an empty name", "none, compact, spread"],
    );
    assert!(!stderr(&o).contains("none was supplied"), "{}", stderr(&o));
    fails_with(
        &["sweep", "--strategies", ",seq", "--quick"],
        &["--strategies has an empty name", "rayon-chunks"],
    );
}

#[test]
fn a_count_out_of_range_names_its_range_not_just_a_lower_bound() {
    fails_with(
        &["validate", "--resolution", "0"],
        &["resolution must be between 4 and 400, not 0"],
    );
    fails_with(
        &["sweep", "--trials=-3"],
        &["trials must be between 1 and 1000"],
    );
    fails_with(
        &["render", "--every", "0"],
        &["steps must be between 1 and 1000000000, not 0"],
    );
}

#[test]
fn list_to_a_full_device_says_it_cannot_write_standard_output_and_exits_1() {
    let o = to_a_full_device(&["list"]);
    assert_eq!(o.status.code(), Some(1));
    let err = stderr(&o);
    assert!(
        err.contains("Error: cannot write to standard output") && err.contains("No space left"),
        "{err}"
    );
}

#[test]
fn a_full_standard_output_is_exit_1_for_every_command_that_prints() {
    let (_tmp, dir) = scratch("full");
    std::fs::create_dir_all(&dir).unwrap();
    let shards: Vec<String> = (1..=2)
        .map(|i| {
            let shard = dir.join(format!("s{i}"));
            let mut args = fake_sweep("rayon-chunks", "1");
            let which = format!("{i}/2");
            args.extend([
                "--shard",
                which.as_str(),
                "--no-plots",
                "--out",
                shard.to_str().unwrap(),
            ]);
            let o = run(&args);
            assert!(o.status.success(), "{}", stderr(&o));
            shard.to_str().unwrap().to_owned()
        })
        .collect();
    let merged = dir.join("merged");
    let mut merge = vec!["merge"];
    merge.extend(shards.iter().map(String::as_str));
    merge.extend(["--out", merged.to_str().unwrap()]);
    let o = to_a_full_device(&merge);
    assert_eq!(o.status.code(), Some(1), "merge: {}", stderr(&o));
    assert!(
        stderr(&o).contains("cannot write to standard output"),
        "{}",
        stderr(&o)
    );
    assert!(
        merged.join("trials.csv").is_file(),
        "the merged files are written"
    );

    let swept = dir.join("swept");
    let mut sweep = fake_sweep("rayon-chunks", "1");
    sweep.extend(["--no-plots", "--out", swept.to_str().unwrap()]);
    let o = to_a_full_device(&sweep);
    assert_eq!(o.status.code(), Some(1), "sweep: {}", stderr(&o));
    for args in [
        vec!["simulate", "--n", "50", "--steps", "1"],
        vec![
            "speedup",
            "--strategy",
            "rayon-chunks",
            "--n",
            "50",
            "--steps",
            "2",
        ],
    ] {
        let o = to_a_full_device(&args);
        assert_eq!(o.status.code(), Some(1), "{args:?}: {}", stderr(&o));
    }
}
