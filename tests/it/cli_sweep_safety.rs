//! `bench-sph sweep` under a busy machine, concurrent use, a closed standard output and an
//! edited results directory: contention is recorded, nothing is lost, nothing panics or hangs.
//! No test asserts a duration.

use std::io::{BufRead, BufReader};
use std::path::Path;
use std::process::{Child, Command, Stdio};

use crate::common::{
    LONG_SWEEP, assert_file_holds, assert_interrupted, bench_sph, no_panic, num, rows, run,
    scratch, start, sweep_command, sweep_into, text, tiny_fake_sweep, tiny_fake_sweep_into,
    wait_until,
};

/// The tiny sweep without charts into `out` (with none, into a new directory under `results/`
/// of its working directory), as a command whose streams the caller sets.
fn tiny_without_plots(out: Option<&Path>) -> Command {
    let mut cmd = bench_sph();
    cmd.args(tiny_fake_sweep()).arg("--no-plots");
    if let Some(dir) = out {
        cmd.arg("--out").arg(dir);
    }
    cmd
}

#[test]
fn fake_contention_marks_cells_contended_and_warns_in_the_output_and_the_report() {
    let (_tmp, dir) = scratch("r");
    let o = tiny_fake_sweep_into(&dir, &["--fake-contention", "0.5"]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let err = text(&o.stderr);
    assert!(err.contains("cores busy with other work"), "{err}");
    assert!(err.contains("saw other work on the machine"), "{err}");
    let summary = rows(&dir.join("summary.csv"));
    assert!(
        summary.iter().all(|r| r["contended"] == "true"),
        "{summary:?}"
    );
    let trials = rows(&dir.join("trials.csv"));
    assert!(trials.iter().all(|r| num(r, "foreign_cpu_s") > 0.0));
    let report = std::fs::read_to_string(dir.join("REPORT.md")).unwrap();
    assert!(report.contains("contended"), "{report}");
}

#[test]
fn a_quiet_fake_machine_gives_no_contended_cell_and_intervals_around_the_mean() {
    let (_tmp, dir) = scratch("r");
    let o = tiny_fake_sweep_into(&dir, &["--no-plots"]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert!(!text(&o.stderr).contains("busy with other work"));
    for r in rows(&dir.join("summary.csv")) {
        assert_eq!(r["contended"], "false", "{r:?}");
        let at = |column: &str| num(&r, column);
        assert!(at("mean_ci_low_s") <= at("mean_s") && at("mean_s") <= at("mean_ci_high_s"));
        if r["strategy"] != "seq" {
            assert!(at("speedup_ci_low") <= at("speedup"));
            assert!(at("speedup") <= at("speedup_ci_high"));
        }
    }
}

/// Busy loops in other processes, one per hardware thread, killed on drop.
struct Busy(Vec<Child>);

impl Busy {
    fn start() -> Busy {
        let hw = std::thread::available_parallelism().map_or(1, |n| n.get());
        Busy(
            (0..hw)
                .map(|_| {
                    Command::new("sh")
                        .args(["-c", "while :; do :; done"])
                        .spawn()
                        .expect("sh runs")
                })
                .collect(),
        )
    }
}

impl Drop for Busy {
    fn drop(&mut self) {
        for c in &mut self.0 {
            let _ = c.kill();
            let _ = c.wait();
        }
    }
}

#[test]
fn a_sweep_beside_busy_processes_measures_their_cpu_and_marks_its_cells_contended() {
    if !Path::new("/proc/stat").exists() {
        return; // Not Linux: the columns stay empty, tested by the unit tests.
    }
    let (_tmp, dir) = scratch("r");
    let _busy = Busy::start();
    let o = sweep_into(
        &dir,
        "--n 1000 --steps 400 --trials 2 --warmup 0 --cores 1 --strategies seq --no-plots",
    );
    assert!(o.status.success(), "{}", text(&o.stderr));
    let err = text(&o.stderr);
    assert!(err.contains("cores busy with other work"), "{err}");
    let summary = rows(&dir.join("summary.csv"));
    assert_eq!(summary[0]["contended"], "true", "{summary:?}");
    for t in rows(&dir.join("trials.csv")) {
        assert!(num(&t, "foreign_cpu_s") > 0.0, "{t:?}");
        assert!(!t["load1"].is_empty());
    }
}

/// Starts a sweep that runs long enough to be caught holding its directory's lock, and waits
/// until it holds it.
fn long_sweep(dir: &Path) -> Child {
    let child = sweep_command(dir, LONG_SWEEP)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let lock = dir.join("bench-sph.lock");
    let holder = format!("sweep {}", child.id());
    wait_until("the sweep never took its lock", || {
        std::fs::read_to_string(&lock).is_ok_and(|s| s.trim() == holder)
    });
    // Its meta.json follows the lock by a moment, longer when the test threads hold both
    // cores; killed before it, the directory would not be a sweep's to resume.
    wait_until("the sweep never wrote its meta.json", || {
        dir.join("meta.json").is_file()
    });
    child
}

#[test]
fn a_second_sweep_on_a_directory_in_use_is_refused_naming_the_holders_pid() {
    let (_tmp, dir) = scratch("r");
    let mut first = long_sweep(&dir);
    let pid = first.id().to_string();
    let o = run(&["sweep", "--resume", dir.to_str().unwrap()]);
    let o2 = tiny_fake_sweep_into(&dir, &["--force"]);
    first.kill().unwrap();
    first.wait().unwrap();
    for o in [o, o2] {
        assert!(!o.status.success());
        no_panic(&o);
        let err = text(&o.stderr);
        assert!(
            err.contains(&format!("is in use by bench-sph sweep (PID {pid})")),
            "{err}"
        );
    }
    // The lock died with its holder: the directory can be resumed now (stopped at once).
    let o = run(&[
        "sweep",
        "--resume",
        dir.to_str().unwrap(),
        "--stop-after-runs",
        "0",
    ]);
    let err = text(&o.stderr);
    assert!(
        !err.contains("in use") && err.contains("interrupted"),
        "{err}"
    );
}

#[test]
fn two_sweeps_racing_for_the_same_new_directory_leave_one_winner_and_a_clear_refusal() {
    let tmp = tempfile::tempdir().unwrap();
    for round in 0..3 {
        let dir = tmp.path().join(format!("same{round}"));
        let spawn = || start(&mut tiny_without_plots(Some(&dir)), Stdio::null());
        let (a, b) = (spawn(), spawn());
        let outs = [a.wait_with_output().unwrap(), b.wait_with_output().unwrap()];
        let ok = outs.iter().filter(|o| o.status.success()).count();
        assert_eq!(ok, 1, "exactly one wins");
        let loser = outs.iter().find(|o| !o.status.success()).unwrap();
        no_panic(loser);
        let err = text(&loser.stderr);
        // Refused while the winner holds the directory, or, once it is done, for its results.
        assert!(
            (err.starts_with(&format!("Error: '{}' is in use by", dir.display()))
                || err.starts_with("Error: results directory"))
                && err.contains(dir.to_str().unwrap())
                && err.lines().count() == 1,
            "{err}"
        );
        assert_eq!(grid_rows(&dir.join("summary.csv")), 3);
    }
}

#[test]
fn default_directories_of_sweeps_started_in_the_same_second_do_not_collide() {
    let tmp = tempfile::tempdir().unwrap();
    let spawn = || {
        start(
            tiny_without_plots(None).current_dir(tmp.path()),
            Stdio::null(),
        )
    };
    let children: Vec<Child> = (0..3).map(|_| spawn()).collect();
    for c in children {
        let o = c.wait_with_output().unwrap();
        assert!(o.status.success(), "{}", text(&o.stderr));
    }
    let dirs: Vec<_> = std::fs::read_dir(tmp.path().join("results"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    assert_eq!(dirs.len(), 3, "{dirs:?}");
    for d in dirs {
        assert_eq!(grid_rows(&d.join("summary.csv")), 3, "{d:?}");
    }
}

#[test]
fn a_closed_standard_output_ends_the_sweep_like_ctrl_c_without_a_panic() {
    let tmp = tempfile::tempdir().unwrap();
    // A reader that goes away at once (`sweep | head -0`).
    let dir = tmp.path().join("pipe");
    let mut child = start(&mut tiny_without_plots(Some(&dir)), Stdio::piped());
    drop(child.stdout.take());
    let o = child.wait_with_output().unwrap();
    assert!(!o.status.success());
    no_panic(&o);
    assert_interrupted(&dir, &text(&o.stderr));
    // And it resumes to the end.
    let o = run(&["sweep", "--resume", dir.to_str().unwrap(), "--no-plots"]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert_eq!(grid_rows(&dir.join("summary.csv")), 3);

    // A full device.
    if Path::new("/dev/full").exists() {
        let dir = tmp.path().join("full");
        let full = std::fs::OpenOptions::new()
            .write(true)
            .open("/dev/full")
            .unwrap();
        let o = tiny_without_plots(Some(&dir))
            .stdout(full)
            .output()
            .unwrap();
        assert!(!o.status.success());
        no_panic(&o);
        let meta = std::fs::read_to_string(dir.join("meta.json")).unwrap();
        assert!(meta.contains("\"status\": \"interrupted\""), "{meta}");
    }
}

#[test]
fn the_plan_of_a_huge_all_pairs_sweep_is_printed_before_any_long_run() {
    let (_tmp, dir) = scratch("r");
    let options = "--n 300000 --strategies seq --cores 1 --steps 1 --trials 1 --no-plots";
    let mut child = sweep_command(&dir, options)
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let mut lines = BufReader::new(child.stdout.take().unwrap()).lines();
    let mut seen = Vec::new();
    // The estimate comes from a bounded sample; the full run (an O(N²) step of 300 000
    // particles) would take minutes. Stop the sweep as soon as the plan is complete.
    for line in lines.by_ref() {
        let line = line.unwrap();
        let done = line.contains("estimated time");
        seen.push(line);
        if done {
            break;
        }
    }
    let _ = child.kill();
    let _ = child.wait();
    let all = seen.join("\n");
    assert!(
        all.contains("group: ") && all.contains("N = 300000"),
        "{all}"
    );
    assert!(all.contains("estimated time: at most about"), "{all}");
}

#[test]
fn resume_rechecks_its_meta_json_and_reruns_corrupt_or_short_cells() {
    let (_tmp, dir) = scratch("r");
    assert!(tiny_fake_sweep_into(&dir, &["--no-plots"]).status.success());
    let d = dir.to_str().unwrap();
    let meta_path = dir.join("meta.json");
    let meta = std::fs::read_to_string(&meta_path).unwrap();

    // meta.json edited to parameters the command line refuses.
    for (from, to, needle) in [
        ("\"trials\": 3", "\"trials\": 0", "trials must be between 1"),
        (
            "\"cores\": [\n      1,\n      2\n    ]",
            "\"cores\": [\n      0\n    ]",
            "cores must be between 1",
        ),
    ] {
        assert!(meta.contains(from), "{meta}");
        std::fs::write(&meta_path, meta.replace(from, to)).unwrap();
        let o = run(&["sweep", "--resume", d, "--no-plots"]);
        assert!(!o.status.success());
        no_panic(&o);
        assert!(text(&o.stderr).contains(needle), "{}", text(&o.stderr));
    }

    // A corrupt trial row: its cell runs again.
    std::fs::write(&meta_path, &meta).unwrap();
    let trials = std::fs::read_to_string(dir.join("trials.csv")).unwrap();
    let mut lines: Vec<String> = trials.lines().map(str::to_owned).collect();
    let fields: Vec<&str> = lines[2].split(',').collect();
    let mut fields: Vec<String> = fields.iter().map(|f| f.to_string()).collect();
    fields[9] = "NaN".into();
    fields[10] = "-5".into();
    lines[2] = fields.join(",");
    std::fs::write(dir.join("trials.csv"), lines.join("\n") + "\n").unwrap();
    let o = run(&["sweep", "--resume", d, "--no-plots"]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    let err = text(&o.stderr);
    assert!(
        err.contains("dropped, will run again") && err.contains("wall_s = NaN"),
        "{err}"
    );
    let again = rows(&dir.join("trials.csv"));
    assert!(again.iter().all(|r| num(r, "wall_s") > 0.0));
    assert_eq!(grid_rows(&dir.join("trials.csv")), 9);

    // trials changed from 3 to 5: every grid cell runs again with 5, and the confirmation,
    // which chose its cells from the grid, runs again too.
    std::fs::write(&meta_path, meta.replace("\"trials\": 3", "\"trials\": 5")).unwrap();
    let o = run(&["sweep", "--resume", d, "--no-plots"]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert!(
        text(&o.stderr).contains("3 rounds, but the sweep's grid phase has 5"),
        "{}",
        text(&o.stderr)
    );
    let summary = rows(&dir.join("summary.csv"));
    let grid: Vec<_> = summary.iter().filter(|r| r["phase"] == "grid").collect();
    assert!(grid.iter().all(|r| r["trials"] == "5"), "{summary:?}");
    assert_eq!(grid_rows(&dir.join("trials.csv")), 15);
    let confirm_runs = rows(&dir.join("trials.csv")).len() - 15;
    assert_eq!(confirm_runs, 9, "3 confirmed cells × 3 rounds, once");
}

/// The rows of a results CSV in the grid phase.
fn grid_rows(path: &Path) -> usize {
    rows(path).iter().filter(|r| r["phase"] == "grid").count()
}

#[test]
fn force_replaces_a_sweeps_earlier_report_and_keeps_foreign_files() {
    let (tmp, dir) = scratch("r");
    assert!(tiny_fake_sweep_into(&dir, &[]).status.success());
    assert!(dir.join("REPORT.md").is_file());
    std::fs::write(dir.join("notes.txt"), "mine").unwrap();
    let o = tiny_fake_sweep_into(&dir, &["--force", "--no-plots"]);
    assert!(o.status.success(), "{}", text(&o.stderr));
    assert!(
        !dir.join("REPORT.md").exists(),
        "no report of the old data stays"
    );
    let pngs = std::fs::read_dir(&dir)
        .unwrap()
        .filter(|e| {
            e.as_ref()
                .unwrap()
                .path()
                .extension()
                .is_some_and(|x| x == "png")
        })
        .count();
    assert_eq!(pngs, 0);
    assert_file_holds(&dir.join("notes.txt"), "mine");

    // A trace's (or any foreign) meta.json is never overwritten, even with --force.
    let other = tmp.path().join("other");
    std::fs::create_dir(&other).unwrap();
    std::fs::write(other.join("meta.json"), "{\"tool\": \"bench-sph trace\"}").unwrap();
    let o = tiny_fake_sweep_into(&other, &["--no-plots"]);
    assert!(!o.status.success());
    assert!(
        text(&o.stderr).contains("'meta.json'"),
        "{}",
        text(&o.stderr)
    );
    let o = tiny_fake_sweep_into(&other, &["--force", "--no-plots"]);
    assert!(!o.status.success());
    assert!(text(&o.stderr).contains("was not written by bench-sph sweep"));
    assert!(
        std::fs::read_to_string(other.join("meta.json"))
            .unwrap()
            .contains("trace")
    );
}

#[test]
fn a_group_larger_than_the_available_memory_is_refused_before_anything_is_written() {
    let (_tmp, dir) = scratch("r");
    let o = sweep_command(&dir, "--n 1000,200000 --neighbors grid --strategies seq")
        .env("BENCH_SPH_FAKE_MEM_AVAILABLE", "10000000")
        .output()
        .unwrap();
    assert!(!o.status.success());
    no_panic(&o);
    let err = text(&o.stderr);
    assert!(
        err.starts_with("Error: the group preset seed, grid, N = 200000")
            && err.contains("needs about")
            && err.contains("available"),
        "{err}"
    );
    assert!(!dir.exists(), "nothing is written");
}

#[test]
fn a_sweep_whose_stdout_and_stderr_are_both_closed_still_exits_cleanly() {
    let (_tmp, dir) = scratch("both");
    // `bench-sph sweep 2>&1 | head -0`: nobody reads either stream.
    let mut child = start(&mut tiny_without_plots(Some(&dir)), Stdio::piped());
    drop(child.stdout.take());
    drop(child.stderr.take());
    let status = child.wait().unwrap();
    assert_eq!(status.code(), Some(1), "an exit, not a signal: {status:?}");
    let meta = std::fs::read_to_string(dir.join("meta.json")).unwrap();
    assert!(meta.contains("\"status\": \"interrupted\""), "{meta}");
}
