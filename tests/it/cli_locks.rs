//! One writer per directory, of any command, for as long as it writes; a refusal names the
//! holder's command and PID. Reading shards for a merge needs no write access and leaves them
//! as they were. No test asserts a duration; waits are bounded.

use std::fs::File;
use std::io::Write;
use std::path::Path;
use std::process::{Child, Command, Stdio};

use crate::common::*;

/// Waits until `dir`'s lock file says `running` holds it for `command`.
fn wait_for_lock(dir: &Path, command: &str, running: &Running) {
    let lock = dir.join("bench-sph.lock");
    let want = format!("{command} {}", running.0.id());
    wait_until(&format!("{command} never took its lock"), || {
        std::fs::read_to_string(&lock).is_ok_and(|s| s.trim() == want)
    });
}

/// A command that runs long enough to be caught holding its directory's lock; killed when
/// dropped, so that a failing test leaves nothing running.
struct Running(Child);

impl Drop for Running {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

fn started(mut cmd: Command) -> Running {
    Running(
        cmd.stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap(),
    )
}

fn stop(running: Running) {
    drop(running);
}

/// A sweep of seq alone, long enough to be caught (it is killed).
fn long_sweep(dir: &Path) -> Running {
    started(sweep_command(dir, LONG_SWEEP))
}

/// A trace of seq over many steps, long enough to be caught (it is killed).
fn long_trace(dir: &Path) -> Running {
    let mut cmd = bench_sph();
    cmd.args([
        "trace",
        "--strategy",
        "seq",
        "--n",
        "3000",
        "--steps",
        "20000",
        "--warmup",
        "0",
        "--out",
    ])
    .arg(dir);
    started(cmd)
}

#[test]
fn a_trace_and_a_sweep_cannot_write_one_directory_at_once() {
    let (_tmp, dir) = scratch("d");
    std::fs::create_dir(&dir).unwrap();
    let trace = long_trace(&dir);
    wait_for_lock(&dir, "trace", &trace);
    let pid = trace.0.id();
    let o = tiny_fake_sweep_into(&dir, &["--no-plots"]);
    stop(trace);
    assert!(!o.status.success());
    no_panic(&o);
    let err = stderr(&o);
    assert!(
        err.contains(&format!(
            "'{}' is in use by bench-sph trace (PID {pid})",
            dir.display()
        )),
        "{err}"
    );
    assert!(!dir.join("summary.csv").exists(), "the sweep wrote nothing");

    // And the other way round.
    let (_tmp2, other) = scratch("e");
    let sweep = long_sweep(&other);
    wait_for_lock(&other, "sweep", &sweep);
    let pid = sweep.0.id();
    let o = run(&[
        "trace",
        "--strategy",
        "seq",
        "--n",
        "60",
        "--out",
        other.to_str().unwrap(),
        "--force",
    ]);
    stop(sweep);
    assert!(!o.status.success());
    let err = stderr(&o);
    assert!(
        err.contains(&format!("is in use by bench-sph sweep (PID {pid})")),
        "{err}"
    );
    assert!(!other.join("trace.json").exists());
}

#[test]
fn every_writer_is_refused_while_a_sweep_holds_the_directory() {
    let (tmp, dir) = scratch("d");
    let finished = tmp.path().join("finished");
    let o = tiny_fake_sweep_into(&finished, &["--no-plots"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let sweep = long_sweep(&dir);
    wait_for_lock(&dir, "sweep", &sweep);
    let pid = sweep.0.id();
    let d = dir.to_str().unwrap();
    let attempts: Vec<Vec<&str>> = vec![
        vec!["report", finished.to_str().unwrap(), "--out", d, "--force"],
        vec![
            "render", "--n", "60", "--steps", "2", "--every", "1", "--frames", d, "--force",
        ],
        vec!["validate", "--resolution", "4", "--out", d, "--force"],
        vec!["sweep", "--resume", d],
    ];
    let outs: Vec<_> = attempts.iter().map(|a| run(a)).collect();
    stop(sweep);
    for (args, o) in attempts.iter().zip(outs) {
        assert!(!o.status.success(), "{args:?}");
        no_panic(&o);
        let err = stderr(&o);
        assert!(
            err.contains(&format!("is in use by bench-sph sweep (PID {pid})")),
            "{args:?}: {err}"
        );
    }
}

/// Every file under `dir` with its bytes and modification time.
fn state(dir: &Path) -> Vec<(String, Vec<u8>, std::time::SystemTime)> {
    let mut out: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| {
            let p = e.unwrap().path();
            let meta = std::fs::metadata(&p).unwrap();
            (
                p.file_name().unwrap().to_string_lossy().into_owned(),
                std::fs::read(&p).unwrap(),
                meta.modified().unwrap(),
            )
        })
        .collect();
    out.sort();
    out
}

/// Makes `dir` and its files read-only (or writable again).
fn read_only(dir: &Path, yes: bool) {
    let mode = |p: &Path, m: u32| {
        use std::os::unix::fs::PermissionsExt;
        std::fs::set_permissions(p, std::fs::Permissions::from_mode(m)).unwrap();
    };
    for e in std::fs::read_dir(dir).unwrap() {
        mode(&e.unwrap().path(), if yes { 0o444 } else { 0o644 });
    }
    mode(dir, if yes { 0o555 } else { 0o755 });
}

#[test]
fn merge_reads_shards_on_a_read_only_directory() {
    let _alone = alone();
    let tmp = tempfile::tempdir().unwrap();
    let shards = two_shards(tmp.path());
    let before: Vec<_> = shards.iter().map(|d| state(d)).collect();
    for d in &shards {
        read_only(d, true);
    }
    let out = tmp.path().join("merged");
    let o = merge(&shards, &out, &[]);
    for d in &shards {
        read_only(d, false);
    }
    assert!(o.status.success(), "{}", stderr(&o));
    // (Run as root, the permissions are not enforced: then at least nothing changed, the
    // lock files' contents included.)
    let after: Vec<_> = shards.iter().map(|d| state(d)).collect();
    assert!(before == after, "a shard changed: {before:?}");
    assert_eq!(rows(&out.join("summary.csv")).len(), 3);
}

#[test]
fn merging_one_directory_twice_says_so_before_anything_else() {
    let _alone = alone();
    let tmp = tempfile::tempdir().unwrap();
    let shards = two_shards(tmp.path());
    let out = tmp.path().join("merged");
    let twice = [shards[0].clone(), shards[0].clone(), shards[1].clone()];
    let o = merge(&twice, &out, &[]);
    assert!(!o.status.success());
    let err = stderr(&o);
    assert!(
        err.starts_with(&format!("Error: '{}' is given twice", shards[0].display()))
            && !err.contains("in use"),
        "{err}"
    );
    assert!(!out.exists());
}

#[test]
fn two_merges_at_once_leave_one_merge_and_a_refusal_that_names_a_merge() {
    let _alone = alone();
    let tmp = tempfile::tempdir().unwrap();
    let shards = two_shards(tmp.path());
    for round in 0..3 {
        let out = tmp.path().join(format!("merged-{round}"));
        let spawn = || start(&mut merge_command(&shards, &out, &[]), Stdio::null());
        let (a, b) = (spawn(), spawn());
        let outs = [a.wait_with_output().unwrap(), b.wait_with_output().unwrap()];
        assert_eq!(outs.iter().filter(|o| o.status.success()).count(), 1);
        let loser = outs.iter().find(|o| !o.status.success()).unwrap();
        no_panic(loser);
        let err = stderr(loser);
        assert!(
            // In use (by the merge; or, while its lock file does not name it yet, by "a
            // process just starting"), or done by then.
            (err.contains("is in use by")
                || err.contains("already holds the output of a bench-sph merge"))
                && !err.contains("sweep"),
            "{err}"
        );
    }
}

#[test]
fn a_merge_holding_its_output_is_named_in_the_refusal() {
    let _alone = alone();
    let tmp = tempfile::tempdir().unwrap();
    let shards = two_shards(tmp.path());
    let out = tmp.path().join("merged");
    std::fs::create_dir(&out).unwrap();
    // Hold the output's lock as a merge does: an OS lock on bench-sph.lock, which names it.
    let mut lock = File::create(out.join("bench-sph.lock")).unwrap();
    lock.try_lock().unwrap();
    writeln!(lock, "merge {}", std::process::id()).unwrap();
    let o = merge(&shards, &out, &[]);
    drop(lock);
    assert!(!o.status.success());
    let err = stderr(&o);
    assert!(
        err.contains(&format!(
            "is in use by bench-sph merge (PID {}); wait for it to finish",
            std::process::id()
        )),
        "{err}"
    );
}

#[test]
fn a_directory_left_by_a_killed_merge_says_what_it_is_and_what_to_do() {
    let _alone = alone();
    let tmp = tempfile::tempdir().unwrap();
    let shards = two_shards(tmp.path());
    let out = tmp.path().join("merged");
    let o = merge(&shards, &out, &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    // Killed before its last file, meta.json (its record already covers all four).
    std::fs::remove_file(out.join("meta.json")).unwrap();

    let o = merge(&shards, &out, &[]);
    assert!(!o.status.success());
    let err = stderr(&o);
    assert!(
        err.contains("the output of a bench-sph merge that was cut short")
            && err.contains("run the merge again with --force")
            && !err.contains("--resume"),
        "{err}"
    );
    let o = run(&["sweep", "--resume", out.to_str().unwrap()]);
    assert!(!o.status.success());
    let err = stderr(&o);
    assert!(
        err.contains("holds the output of a bench-sph merge that was cut short")
            && err.contains("--force")
            && !err.contains("not a sweep's results directory"),
        "{err}"
    );
    let o = merge(&shards, &out, &["--force"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(out.join("meta.json").is_file());
}
