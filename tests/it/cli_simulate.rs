//! `bench-sph simulate` driven through the built binary: output, dump round trip, and a clear
//! `Error: ...` with a non-zero exit for each kind of bad input.

use std::path::Path;
use std::process::{Command, Stdio};
use std::time::Duration;

use crate::common::{
    DIVERGING_INIT, assert_holds_all, bench_sph, fails_with, names, run, scratch, start, stderr,
    stdout, wait_until,
};

fn write(dir: &Path, name: &str, text: &str) -> String {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path.to_str().unwrap().to_owned()
}

#[test]
fn json_output_carries_the_run_and_its_configuration() {
    let o = run(&["simulate", "--n", "50", "--steps", "5", "--json"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_str(stdout(&o).trim()).expect("one JSON object");
    assert_eq!(v["n"], 50);
    assert_eq!(v["steps"], 5);
    assert_eq!(v["preset"], "seed");
    assert_eq!(v["neighbors"], "all-pairs");
    assert_eq!(v["order"], "index");
    assert_eq!(v["strategy"], "seq");
    assert!(v["wall_s"].as_f64().unwrap() > 0.0);
    assert!(v["cpu_s"].as_f64().unwrap() >= 0.0);
    assert!(
        v.get("passes_alone").is_none(),
        "no strategy runs passes alone any more, so no run reports them"
    );
    assert!(v["particle_steps_per_s"].as_f64().unwrap() > 0.0);
    assert_eq!(v["checksum"].as_str().unwrap().len(), 16);
}

#[test]
fn cell_order_is_a_grid_option_with_its_own_bits_the_same_on_every_strategy() {
    // 200 steps: the dam has collapsed, so the particles' numbers no longer follow the cells.
    let grid = [
        "simulate",
        "--n",
        "400",
        "--steps",
        "200",
        "--neighbors",
        "grid",
    ];
    let checksum = |extra: &[&str]| -> String {
        let o = run(&[&grid[..], extra, &["--json"]].concat());
        assert!(o.status.success(), "{extra:?}: {}", stderr(&o));
        let v: serde_json::Value = serde_json::from_str(stdout(&o).trim()).unwrap();
        let order = if extra.contains(&"cell") {
            "cell"
        } else {
            "index"
        };
        assert_eq!(v["order"], order, "{extra:?}");
        v["checksum"].as_str().unwrap().to_owned()
    };
    let cell = checksum(&["--order", "cell"]);
    assert_ne!(cell, checksum(&[]), "cell order sums in another order");
    for parallel in [
        [
            "--strategy",
            "rayon-chunks",
            "--cores",
            "2",
            "--chunks",
            "7",
        ],
        [
            "--strategy",
            "crossbeam-pool",
            "--cores",
            "3",
            "--chunks",
            "64",
        ],
        ["--strategy", "rayon-spawn", "--cores", "2", "--chunks", "1"],
    ] {
        assert_eq!(
            checksum(&[&["--order", "cell"][..], &parallel].concat()),
            cell
        );
    }
    let o = run(&[&grid[..], &["--order", "cell"]].concat());
    assert!(o.status.success(), "{}", stderr(&o));
    assert_holds_all("stdout", &stdout(&o), &["sums in cell order"]);
    fails_with(
        &["simulate", "--n", "40", "--steps", "2", "--order", "cell"],
        &["Error: --order cell needs --neighbors grid"],
    );
}

#[test]
fn text_output_names_n_steps_wall_and_cpu_time() {
    let o = run(&[
        "simulate",
        "--n",
        "40",
        "--steps",
        "3",
        "--neighbors",
        "grid",
        "--preset",
        "cpp",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let needles = [
        "N = 40",
        "3 steps",
        "wall",
        "CPU",
        "particle-steps/s",
        "checksum",
        "cpp",
        "grid",
    ];
    assert_holds_all("stdout", &stdout(&o), &needles);
}

#[test]
fn a_dump_loads_back_with_init_and_continues_exactly_as_an_unbroken_run() {
    let dir = tempfile::tempdir().unwrap();
    let dump = dir.path().join("half.csv");
    let dump = dump.to_str().unwrap();
    let json = |args: &[&str]| -> serde_json::Value {
        let o = run(args);
        assert!(o.status.success(), "{}", stderr(&o));
        serde_json::from_str(stdout(&o).trim()).unwrap()
    };
    let whole = json(&["simulate", "--n", "300", "--steps", "40", "--json"]);
    json(&[
        "simulate", "--n", "300", "--steps", "20", "--dump", dump, "--json",
    ]);
    let text = std::fs::read_to_string(dump).unwrap();
    assert!(
        text.starts_with("# bench-sph dump: preset=seed n=300 step=20\ni,x,y,vx,vy,fx,fy,rho,p\n")
    );
    assert_eq!(text.lines().count(), 302);
    let resumed = json(&["simulate", "--init", dump, "--steps", "20", "--json"]);
    assert_eq!(resumed["n"], 300);
    assert_eq!(resumed["checksum"], whole["checksum"]);
}

#[test]
fn init_accepts_any_column_order_and_ignores_extra_columns() {
    let dir = tempfile::tempdir().unwrap();
    let f = write(dir.path(), "s.csv", "note,y,x\na,100,200\nb,100.5,210\n");
    let o = run(&["simulate", "--init", &f, "--steps", "2", "--json"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stdout(&o).contains("\"n\":2"));
}

#[test]
fn a_diverging_run_is_an_error_naming_step_and_particle_and_its_dump_shows_the_state() {
    let dir = tempfile::tempdir().unwrap();
    let f = write(dir.path(), "boom.csv", DIVERGING_INIT);
    let dump = dir.path().join("out.csv");
    fails_with(
        &["simulate", "--init", &f, "--dump", dump.to_str().unwrap()],
        &["Error:", "diverged at step 1", "particle 0"],
    );
    assert!(std::fs::read_to_string(&dump).unwrap().contains("inf"));
}

#[test]
fn bad_init_files_give_one_clear_error_with_the_line() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    fails_with(
        &["simulate", "--init", "/no/such/file.csv"],
        &["Error:", "cannot read init file", "/no/such/file.csv"],
    );
    fails_with(
        &["simulate", "--init", &write(d, "empty.csv", "")],
        &["Error:", "holds no particles"],
    );
    fails_with(
        &["simulate", "--init", &write(d, "header.csv", "x,y\n")],
        &["Error:", "holds no particles"],
    );
    fails_with(
        &["simulate", "--init", &write(d, "noy.csv", "x,vx\n1,2\n")],
        &["Error:", "missing column 'y'"],
    );
    fails_with(
        &[
            "simulate",
            "--init",
            &write(d, "nan.csv", "x,y\n100,100\n200,abc\n"),
        ],
        &["Error:", "line 3", "column 'y'", "'abc'"],
    );
    fails_with(
        &["simulate", "--init", &write(d, "inf.csv", "x,y\n100,NaN\n")],
        &["Error:", "line 2", "not a finite number"],
    );
    fails_with(
        &[
            "simulate",
            "--init",
            &write(d, "ragged.csv", "x,y\n100,100\n1,2,3\n"),
        ],
        &["Error:", "line 3"],
    );
    fails_with(
        &[
            "simulate",
            "--init",
            &write(d, "out.csv", "x,y\n100,100\n5000,100\n"),
        ],
        &["Error:", "line 3", "outside the walls"],
    );
    fails_with(
        &[
            "simulate",
            "--init",
            &write(d, "two.csv", "x,y\n100,100\n200,100\n"),
            "--n",
            "3",
        ],
        &["Error:", "--n 3 conflicts", "2 particles"],
    );
}

#[test]
fn bad_numbers_and_names_are_refused_before_anything_runs() {
    fails_with(&["simulate", "--n", "0"], &["--n", "between 1 and"]);
    fails_with(&["simulate", "--steps", "0"], &["--steps", "between 1 and"]);
    fails_with(&["simulate", "--cores", "0"], &["--cores", "between 1 and"]);
    fails_with(
        &["simulate", "--chunks", "0"],
        &["--chunks", "between 1 and"],
    );
    fails_with(&["simulate", "--n", "-5"], &["-5"]);
    fails_with(&["simulate", "--steps", "ten"], &["ten"]);
    fails_with(
        &["simulate", "--strategy", "turbo"],
        &["unknown strategy 'turbo'", "seq"],
    );
    fails_with(
        &["simulate", "--preset", "python"],
        &["python", "seed", "cpp"],
    );
    fails_with(
        &["simulate", "--neighbors", "octree"],
        &["octree", "all-pairs", "grid"],
    );
}

#[test]
fn an_unwritable_dump_path_fails_before_the_run() {
    let o = run(&[
        "simulate",
        "--n",
        "10",
        "--steps",
        "100000000",
        "--dump",
        "/no/such/dir/out.csv",
    ]);
    assert!(!o.status.success());
    let err = stderr(&o);
    assert!(
        err.starts_with("Error: cannot write '/no/such/dir/out.csv'"),
        "{err}"
    );
}

#[test]
fn list_prints_one_strategy_per_line_name_first() {
    let o = run(&["list"]);
    assert!(o.status.success());
    let out = stdout(&o);
    let names: Vec<&str> = out
        .lines()
        .map(|l| l.split_whitespace().next().unwrap())
        .collect();
    assert_eq!(names, sph_strategies::StrategyName::names());
    assert!(
        out.lines().all(|l| l.split_whitespace().count() > 3),
        "each line has a description"
    );
}

#[test]
fn a_failed_run_leaves_an_existing_dump_file_as_it_was() {
    let dir = tempfile::tempdir().unwrap();
    let dump = write(dir.path(), "final.csv", "earlier results\n");
    // A worker's panic made into an error of the run (its message says "panicked").
    let o = run(&[
        "simulate",
        "--n",
        "50",
        "--steps",
        "5",
        "--inject-panic-at",
        "7",
        "--dump",
        &dump,
    ]);
    assert!(!o.status.success());
    assert!(
        stderr(&o).contains("Error: step 1 failed"),
        "{}",
        stderr(&o)
    );
    fails_with(&["simulate", "--dump", &dump, "--steps", "zero"], &["zero"]);
    assert_eq!(std::fs::read_to_string(&dump).unwrap(), "earlier results\n");
    assert_eq!(
        names(dir.path()),
        ["final.csv"],
        "no temporary file is left"
    );
}

#[test]
fn a_dump_of_one_preset_continues_only_with_that_preset_or_an_explicit_other() {
    let dir = tempfile::tempdir().unwrap();
    let dump = dir.path().join("cpp.csv");
    let dump = dump.to_str().unwrap();
    let o = run(&[
        "simulate", "--preset", "cpp", "--n", "100", "--steps", "3", "--dump", dump,
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    fails_with(
        &["simulate", "--init", dump, "--steps", "1"],
        &[&format!(
            "Error: init file '{dump}' was dumped with --preset cpp; pass --preset cpp to \
             continue it, or --preset seed explicitly to use seed physics"
        )],
    );
    for preset in ["cpp", "seed"] {
        let o = run(&[
            "simulate", "--init", dump, "--steps", "1", "--preset", preset, "--json",
        ]);
        assert!(o.status.success(), "{preset}: {}", stderr(&o));
        assert!(stdout(&o).contains(&format!("\"preset\":\"{preset}\"")));
    }
    // A dump from before the info line (no comment) loads with the default preset.
    let text = std::fs::read_to_string(dump).unwrap();
    let old = write(dir.path(), "old.csv", text.split_once('\n').unwrap().1);
    let o = run(&["simulate", "--init", &old, "--steps", "1"]);
    assert!(o.status.success(), "{}", stderr(&o));
}

/// Runs `args` and returns its stderr, failing the test if it takes more than 30 s.
fn stderr_within_30_s(args: &[&str]) -> String {
    let mut cmd = assert_cmd::Command::from_std(bench_sph());
    let ended = cmd.args(args).timeout(Duration::from_secs(30)).assert();
    let o = ended.failure().get_output().clone();
    assert!(
        o.status.code().is_some(),
        "{args:?} did not end within 30 s"
    );
    stderr(&o)
}

#[test]
fn an_endless_init_device_is_refused_at_its_first_overlong_line() {
    let err = stderr_within_30_s(&["simulate", "--init", "/dev/zero"]);
    assert_eq!(
        err,
        "Error: init file '/dev/zero': line 1 is longer than 4096 bytes (is this a CSV file?)\n"
    );
}

#[test]
fn an_init_line_over_4_kib_is_refused_with_its_number_and_a_directory_as_a_directory() {
    let dir = tempfile::tempdir().unwrap();
    let long = format!("x,y,note\n100,100,a\n100,116,{}\n", "b".repeat(5000));
    fails_with(
        &["simulate", "--init", &write(dir.path(), "long.csv", &long)],
        &["Error:", "line 3 is longer than 4096 bytes"],
    );
    let d = dir.path().to_str().unwrap();
    fails_with(
        &["simulate", "--init", d],
        &[&format!(
            "Error: init file '{d}' is a directory, not a CSV file"
        )],
    );
}

#[test]
fn a_run_larger_than_the_available_memory_is_refused_before_allocating() {
    let o = bench_sph()
        .args(["simulate", "--n", "100000000", "--neighbors", "grid"])
        .env("BENCH_SPH_FAKE_MEM_AVAILABLE", "9000000000")
        .output()
        .unwrap();
    assert!(!o.status.success());
    assert_eq!(
        stderr(&o),
        "Error: --n 100000000 needs about 17 GB of memory (grid search); \
         this machine has 9.0 GB available\n"
    );
    fails_with(
        &["simulate", "--n", "18446744073709551615"],
        &["particles must be between 1 and 100000000"],
    );
}

#[test]
fn a_full_or_closed_stdout_is_one_error_line_not_a_panic() {
    let o = bench_sph()
        .args(["simulate", "--n", "20", "--steps", "2"])
        .stdout(std::fs::File::create("/dev/full").unwrap())
        .output()
        .unwrap();
    assert!(!o.status.success());
    assert_eq!(
        stderr(&o),
        "Error: cannot write to standard output: No space left on device (os error 28)\n"
    );
}

#[test]
fn ctrl_c_during_a_dumping_run_keeps_the_earlier_file_and_leaves_no_temporary() {
    let (tmp, dump) = scratch("d.csv");
    std::fs::write(&dump, "keep").unwrap();
    let child = start(
        bench_sph()
            .args(["simulate", "--n", "3000", "--steps", "1000000", "--dump"])
            .arg(&dump),
        Stdio::null(),
    );
    let temporaries = || {
        std::fs::read_dir(tmp.path())
            .unwrap()
            .filter(|e| {
                e.as_ref()
                    .unwrap()
                    .file_name()
                    .to_string_lossy()
                    .ends_with(".tmp")
            })
            .count()
    };
    // Wait for the temporary file: the run is under way.
    wait_until("the run never started its dump", || temporaries() > 0);
    let killed = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(killed.success());
    let o = child.wait_with_output().unwrap();
    assert_eq!(o.status.code(), Some(130), "{o:?}");
    assert_eq!(std::fs::read_to_string(&dump).unwrap(), "keep");
    assert_eq!(temporaries(), 0, "a temporary file was left behind");
}

#[test]
fn wcsph_reports_its_resolution_walls_and_simulated_time() {
    let o = run(&[
        "simulate",
        "--preset",
        "wcsph",
        "--resolution",
        "6",
        "--neighbors",
        "grid",
        "--t-end",
        "0.01",
        "--json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_str(stdout(&o).trim()).expect("one JSON object");
    assert_eq!(v["preset"], "wcsph");
    assert_eq!(
        (v["n"].as_u64(), v["resolution"].as_u64()),
        (Some(72), Some(6))
    );
    assert!(v["walls"].as_u64().unwrap() > 0);
    // No jitter, so no seed.
    assert!(v["seed"].is_null());
    let t = v["simulated_s"].as_f64().unwrap();
    let steps = v["steps"].as_u64().unwrap();
    assert!(t >= 0.01 && steps > 1, "{t} s after {steps} steps");
}

#[test]
fn wcsph_maps_n_to_the_nearest_resolution_and_says_so() {
    let o = run(&[
        "simulate", "--preset", "wcsph", "--n", "100", "--steps", "2",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_holds_all(
        "stderr",
        &stderr(&o),
        &["resolution R = 7", "98 fluid particles"],
    );
    assert_holds_all(
        "stdout",
        &stdout(&o),
        &["N = 98 particles", "resolution R = 7"],
    );
}

#[test]
fn wcsph_options_that_do_not_fit_are_clear_errors() {
    fails_with(
        &["simulate", "--resolution", "10", "--steps", "1"],
        &["--resolution applies to --preset wcsph only"],
    );
    fails_with(
        &["simulate", "--preset", "wcsph", "--resolution", "3"],
        &["resolution"],
    );
    fails_with(&["simulate", "--t-end", "0"], &["above 0"]);
    fails_with(
        &["simulate", "--steps", "5", "--t-end", "1"],
        &["cannot be used with"],
    );
    let (dir, _) = scratch("unused");
    let init = write(dir.path(), "init.csv", "x,y\n100,100\n");
    fails_with(
        &["simulate", "--preset", "wcsph", "--init", &init],
        &["cannot start --preset wcsph"],
    );
}
