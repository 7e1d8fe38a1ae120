//! Helpers shared by the integration tests that drive the `bench-sph` binary: runs through
//! `assert_cmd` (whose failures show the command, its exit and both streams), with
//! `predicates` for what standard error must hold.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::sync::{Mutex, MutexGuard};
use std::time::{Duration, Instant};

use assert_cmd::assert::Assert;
use predicates::prelude::*;
use predicates::str::contains;
use tempfile::TempDir;

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

/// Starts `cmd` with standard output to `stdout` and standard error piped, to be read with
/// `wait_with_output`.
pub fn start(cmd: &mut Command, stdout: Stdio) -> Child {
    cmd.stdout(stdout)
        .stderr(Stdio::piped())
        .spawn()
        .expect("binary starts")
}

/// `bench-sph sweep` with `options`, then `--out dir`, ready to run or start. The options are
/// written as on a command line, in one string split at white space (no value here holds a
/// space).
pub fn sweep_command(dir: &Path, options: &str) -> Command {
    let mut cmd = bench_sph();
    cmd.arg("sweep")
        .args(options.split_whitespace())
        .arg("--out")
        .arg(dir);
    cmd
}

/// Runs [`sweep_command`] to the end, whatever its outcome.
pub fn sweep_into(dir: &Path, options: &str) -> Output {
    sweep_command(dir, options).output().expect("binary runs")
}

/// The arguments of a small sweep timed by the hidden `--fake-timings`, so that every number
/// it reports is known: N = 60 over 3 steps, no warm-up, 3 trials a cell at 1 and 2 cores and
/// 4 chunks, of `strategies` (comma-separated), the trials' times taken in turn from `timings`
/// (seconds, comma-separated). Callers add `--out` and whatever else they test.
pub fn fake_sweep<'a>(strategies: &'a str, timings: &'a str) -> Vec<&'a str> {
    let mut args: Vec<&str> =
        "sweep --n 60 --steps 3 --trials 3 --warmup 0 --cores 1..2 --chunks 4"
            .split_whitespace()
            .collect();
    args.extend(["--strategies", strategies, "--fake-timings", timings]);
    args
}

/// The tiny sweep under fake times that tests of a results directory start from: seq and
/// rayon-chunks on [`fake_sweep`]'s plan, 3 cells of 3 trials. Callers add `--out` and
/// whatever else they test.
pub fn tiny_fake_sweep() -> Vec<&'static str> {
    fake_sweep("seq,rayon-chunks", "1.0,1.1,0.9,0.5,0.55,0.6")
}

/// Runs [`tiny_fake_sweep`] into `dir`, then `extra`, to the end, whatever its outcome.
pub fn tiny_fake_sweep_into(dir: &Path, extra: &[&str]) -> Output {
    run(&[
        &tiny_fake_sweep()[..],
        &["--out", dir.to_str().unwrap()],
        extra,
    ]
    .concat())
}

/// A finished [`tiny_fake_sweep`] in `dir`, with `extra` (its report and charts unless
/// `extra` says `--no-plots`); fails the test if the sweep fails.
pub fn swept(dir: &Path, extra: &[&str]) {
    let o = tiny_fake_sweep_into(dir, extra);
    assert!(o.status.success(), "{}", stderr(&o));
}

/// The options of a sweep of seq alone that runs for minutes: long enough to be caught
/// holding its directory (the tests that start it kill it).
pub const LONG_SWEEP: &str =
    "--n 2000 --steps 1000 --trials 50 --cores 1 --strategies seq --no-plots";

/// Held by every test that runs shards (one sweep after another) for its whole run, so that
/// no two such tests overlap: all the tests run on parallel threads of one process.
static ONE_AT_A_TIME: Mutex<()> = Mutex::new(());

/// Waits until no other test holds [`ONE_AT_A_TIME`], then holds it until the guard drops (a
/// failed test's poison does not matter here).
pub fn alone() -> MutexGuard<'static, ()> {
    ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner())
}

/// Two shards of a 3-cell plan (seq and rayon-chunks at 1..2 cores, 2 chunks, under fake
/// times), one after the other, under `root`; returns their directories.
pub fn two_shards(root: &Path) -> Vec<PathBuf> {
    (1..=2)
        .map(|i| {
            let dir = root.join(format!("shard-{i}"));
            let o = sweep_into(
                &dir,
                &format!(
                    "--n 60 --steps 3 --trials 2 --warmup 0 --cores 1..2 --chunks 2 \
                     --strategies rayon-chunks --confirm-rounds 0 --fake-timings 1,1.1,0.9 \
                     --no-plots --shard {i}/2"
                ),
            );
            assert!(o.status.success(), "{}", stderr(&o));
            dir
        })
        .collect()
}

/// The plan that the merge tests shard in three: 1 group: seq, rayon-chunks at 1..2 cores ×
/// chunks 2,4 and std-static at 1..2 cores: 7 cells, 6 of them dealt to shards (shard 2/3
/// holds seq, rayon-chunks at 1 core and 4 chunks, and std-static at 1 core); no
/// confirmation (a shard has none, and an unsharded sweep compared with the merge must have
/// the same plan).
pub const SHARDED_PLAN: &str = "--n 60 --steps 3 --trials 2 --warmup 0 --cores 1..2 \
                                --chunks 2,4 --strategies rayon-chunks,std-static \
                                --confirm-rounds 0 --fake-timings 1,1.1,0.9 --no-plots";

/// Runs a sweep of [`SHARDED_PLAN`] with `extra` into `dir`; fails the test if it fails.
pub fn sweep_plan(dir: &Path, extra: &str) -> Output {
    let o = sweep_into(dir, &format!("{SHARDED_PLAN} {extra}"));
    assert!(o.status.success(), "{}", stderr(&o));
    o
}

/// Shards 1/3, 2/3 and 3/3 of [`SHARDED_PLAN`], run one after another, under `root`;
/// returns their directories. (Callers hold [`alone`].)
pub fn three_shards(root: &Path) -> Vec<PathBuf> {
    (1..=3)
        .map(|i| {
            let dir = root.join(format!("shard-{i}"));
            sweep_plan(&dir, &format!("--shard {i}/3"));
            dir
        })
        .collect()
}

/// `bench-sph merge` of `dirs` into `out`, then `extra`, ready to run or start.
pub fn merge_command(dirs: &[PathBuf], out: &Path, extra: &[&str]) -> Command {
    let mut cmd = bench_sph();
    cmd.arg("merge")
        .args(dirs)
        .arg("--out")
        .arg(out)
        .args(extra);
    cmd
}

/// Runs [`merge_command`] to the end, whatever its outcome.
pub fn merge(dirs: &[PathBuf], out: &Path, extra: &[&str]) -> Output {
    merge_command(dirs, out, extra)
        .output()
        .expect("binary runs")
}

/// Copies the files of `from` (not its directories) into `to`, made if missing.
pub fn copy_dir(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for e in std::fs::read_dir(from).unwrap() {
        let e = e.unwrap();
        if e.path().is_file() {
            std::fs::copy(e.path(), to.join(e.file_name())).unwrap();
        }
    }
}

/// Checks `ready` every `every` until it holds or `limit` has passed; says whether it held.
pub fn poll_until(limit: Duration, every: Duration, mut ready: impl FnMut() -> bool) -> bool {
    let deadline = Instant::now() + limit;
    loop {
        if ready() {
            return true;
        }
        if Instant::now() >= deadline {
            return false;
        }
        std::thread::sleep(every);
    }
}

/// Waits until `ready` holds, checking every 20 ms; fails the test with `never` if it does not
/// within a minute (a bound on a hang, not a timing).
pub fn wait_until(never: &str, ready: impl FnMut() -> bool) {
    let held = poll_until(Duration::from_secs(60), Duration::from_millis(20), ready);
    assert!(held, "{never}");
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

/// Asserts that `text` (named `what` in the failure) holds every one of `needles`.
pub fn assert_holds_all(what: &str, text: &str, needles: &[&str]) {
    for needle in needles {
        assert!(text.contains(needle), "{what} lacks {needle:?}:\n{text}");
    }
}

/// The first line of `text` that holds `needle`; fails the test, showing `text`, if none does.
pub fn line_containing<'a>(text: &'a str, needle: &str) -> &'a str {
    text.lines()
        .find(|l| l.contains(needle))
        .unwrap_or_else(|| panic!("no line holds {needle:?}:\n{text}"))
}

/// A run's standard output as text.
pub fn stdout(o: &Output) -> String {
    text(&o.stdout)
}

/// A run's standard error as text.
pub fn stderr(o: &Output) -> String {
    text(&o.stderr)
}

/// A new temporary directory (removed when the returned guard drops) and the path `name`
/// inside it, not yet created.
pub fn scratch(name: &str) -> (TempDir, PathBuf) {
    let tmp = tempfile::tempdir().unwrap();
    let path = tmp.path().join(name);
    (tmp, path)
}

/// An init file's text whose two particles start at velocities of ±1e308: the first step
/// overflows.
pub const DIVERGING_INIT: &str = "x,y,vx,vy\n500,500,0,1e308\n505,500,0,-1e308\n";

/// Asserts that the file at `path` holds exactly `text` (a file the run had to leave alone).
pub fn assert_file_holds(path: &Path, text: &str) {
    let held = std::fs::read_to_string(path).unwrap();
    assert_eq!(held, text, "{}", path.display());
}

/// The JSON document in the file at `path` (a `meta.json`, a `trace.json`, a record); fails
/// the test if it is missing or not JSON.
pub fn read_json(path: &Path) -> serde_json::Value {
    let text = std::fs::read_to_string(path).unwrap();
    serde_json::from_str(&text).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// bench-sph's bookkeeping in a directory it writes: the lock file and the record of the files
/// it wrote.
pub const BOOKKEEPING: [&str; 2] = ["bench-sph.lock", "bench-sph-files.json"];

/// The names of the entries of `dir`, sorted, without bench-sph's [`BOOKKEEPING`].
pub fn names(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| !BOOKKEEPING.contains(&n.as_str()))
        .collect();
    v.sort();
    v
}

/// `dir`'s record of the files bench-sph wrote there: file name → command (`sweep`,
/// `report`, …); empty without a record.
pub fn record(dir: &Path) -> HashMap<String, String> {
    let Ok(text) = std::fs::read_to_string(dir.join("bench-sph-files.json")) else {
        return HashMap::new();
    };
    let value: serde_json::Value = serde_json::from_str(&text).unwrap();
    value["files"]
        .as_object()
        .unwrap()
        .iter()
        .map(|(k, v)| (k.clone(), v.as_str().unwrap().to_owned()))
        .collect()
}

/// Runs `cmd` to the end with its streams captured, but for a minute at most: a command that
/// has not finished by then (waiting on a FIFO, reading an endless device) is killed and the
/// test fails. A bound on a hang, not a timing.
pub fn output_within_a_minute(mut cmd: Command) -> Output {
    let child = cmd
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("binary starts");
    let pid = child.id();
    let (done, finished) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let _ = done.send(child.wait_with_output());
    });
    match finished.recv_timeout(Duration::from_secs(60)) {
        Ok(output) => output.expect("binary runs"),
        Err(_) => {
            let _ = Command::new("kill").args(["-9", &pid.to_string()]).status();
            panic!("{cmd:?} did not finish within a minute (killed): it hung on its input")
        }
    }
}

/// A PNG's (width, height) in pixels, decoding the whole image; fails the test if it does not
/// decode.
pub fn png_size(path: &Path) -> (u32, u32) {
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(path).unwrap()));
    let mut reader = decoder.read_info().expect("a PNG header");
    let mut buf = vec![0; reader.output_buffer_size().expect("a buffer size")];
    let info = reader.next_frame(&mut buf).expect("the PNG decodes");
    (info.width, info.height)
}

/// The number in `row`'s `column`; fails the test, showing the row, if it is not one.
pub fn num(row: &Row, column: &str) -> f64 {
    row[column]
        .parse()
        .unwrap_or_else(|_| panic!("{column} = {:?} in {row:?}", row[column]))
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

/// Checks that a sweep into `dir` stopped as interrupted: its standard error `err` says so and
/// how to resume, and its `meta.json` records the status.
pub fn assert_interrupted(dir: &Path, err: &str) {
    assert!(
        err.contains("Error: interrupted") && err.contains("--resume"),
        "{err}"
    );
    let meta = std::fs::read_to_string(dir.join("meta.json")).unwrap();
    assert!(meta.contains("\"status\": \"interrupted\""), "{meta}");
}

/// Fails the test if the command panicked.
pub fn no_panic(o: &Output) {
    let err = text(&o.stderr);
    assert!(!err.contains("panicked"), "panicked:\n{err}");
}

/// Rewrites `dir/meta.json` so that `set` holds for its top level (the first session's
/// machine and build) and for every session: `set` gets each of those JSON objects in turn.
/// How tests make a sweep look measured on another machine or by another build.
pub fn set_in_meta(dir: &Path, mut set: impl FnMut(&mut serde_json::Value)) {
    let path = dir.join("meta.json");
    let mut meta = read_json(&path);
    set(&mut meta);
    for s in meta["sessions"].as_array_mut().unwrap() {
        set(s);
    }
    std::fs::write(&path, serde_json::to_string_pretty(&meta).unwrap()).unwrap();
}
