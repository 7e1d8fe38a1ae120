//! `sweep --anchor PATH`: the plain C++ loop's OpenMP build run beside the cells
//! ([`crate::results::anchor`]). After the cells, for each group of the `seed` preset with
//! all-pairs (what the plain loop computes), the program runs as `PATH N STEPS SEED` with
//! `OMP_NUM_THREADS` set to each of the sweep's core counts (and 1, its reference), in
//! `--trials` rounds, each round's thread counts in a shuffled order as the cells' are
//! ([`super::schedule`]). Its time is the one it prints (its steps, without starting the
//! process); its checksum is the group's `seq` checksum when it computed the same state.

use std::io::Read;
use std::path::Path;
use std::process::{Child, Command, ExitStatus, Stdio};
use std::sync::mpsc;
use std::time::{Duration, Instant};

use anyhow::{Context, bail};
use serde::Deserialize;
use sph_solver::models::Preset;
use sph_solver::sph::neighbors::NeighborMode;

use super::params::SweepParams;
use super::schedule::{Schedule, order};
use crate::results::anchor::AnchorRun;
use crate::results::key::Group;
use crate::results::rows::Phase;

/// Whether the plain loop computes `group`'s workload.
pub fn applies(group: &Group) -> bool {
    group.preset == Preset::Seed && group.neighbors == NeighborMode::AllPairs
}

/// Refuses an anchor that is not an executable file, or a sweep with no group it applies to.
pub fn check(params: &SweepParams, path: &Path) -> anyhow::Result<()> {
    if !path.is_file() {
        bail!("--anchor '{}': no such program", path.display());
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        let mode = std::fs::metadata(path)?.permissions().mode();
        if mode & 0o111 == 0 {
            bail!(
                "--anchor '{}': not executable (chmod +x it, or build it with \
                 scripts/build-plain-loop.sh)",
                path.display()
            );
        }
    }
    if !(params.presets.contains(&Preset::Seed)
        && params.neighbors.contains(&NeighborMode::AllPairs))
    {
        bail!(
            "--anchor: the plain loop computes the seed preset with all-pairs, and this sweep \
             has no such group (add --preset seed --neighbors all-pairs)"
        );
    }
    Ok(())
}

/// What the plain loop prints.
#[derive(Debug, Deserialize)]
struct Printed {
    n: usize,
    steps: usize,
    wall_s: f64,
    checksum: String,
}

/// Runs the anchor of `group` at `threads` (1 added where missing) for `rounds` rounds, each
/// run allowed `limit`, and returns its runs; `None` when a signal asked the sweep to stop.
pub fn measure(
    path: &Path,
    group: &Group,
    threads: &[usize],
    params: &SweepParams,
    hardware: usize,
    limit: Duration,
) -> anyhow::Result<Option<Vec<AnchorRun>>> {
    let mut counts = threads.to_vec();
    counts.push(1);
    counts.sort_unstable();
    counts.dedup();
    let schedule = order(
        Schedule::Rounds,
        &counts,
        params.trials,
        params.seed,
        group,
        Phase::Grid,
    );
    let mut runs = Vec::with_capacity(schedule.len());
    for run in schedule {
        if crate::signals::requested() {
            return Ok(None);
        }
        let t = run.cell;
        let Some(printed) = run_once(path, group, t, params.seed, limit)
            .with_context(|| format!("--anchor '{}' on {t} threads", path.display()))?
        else {
            return Ok(None);
        };
        runs.push(AnchorRun {
            n: group.n,
            steps: group.steps,
            seed: params.seed,
            threads: t,
            round: run.round,
            position: run.position,
            wall_s: printed.wall_s,
            checksum: printed.checksum,
            oversubscribed: t > hardware,
        });
    }
    Ok(Some(runs))
}

/// One run of the program: what it printed, checked against what it was asked; `None` when a
/// signal asked the sweep to stop (the program is then killed, and its end is no error).
fn run_once(
    path: &Path,
    group: &Group,
    threads: usize,
    seed: u64,
    limit: Duration,
) -> anyhow::Result<Option<Printed>> {
    let mut child = Command::new(path)
        .args([
            group.n.to_string(),
            group.steps.to_string(),
            seed.to_string(),
        ])
        .env("OMP_NUM_THREADS", threads.to_string())
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .context("cannot start it")?;
    // Both pipes are read while it runs, so that no amount of output stalls it.
    let out = drain(child.stdout.take());
    let err = drain(child.stderr.take());
    let ended = wait_within(&mut child, limit);
    if !matches!(ended, Ok(Some(_))) {
        // Stopped, hung or unwaitable: it must not outlive the sweep (best effort: it may
        // have ended in between).
        let _ = child.kill();
        let _ = child.wait();
    }
    let status = match ended? {
        Some(status) => status,
        None if crate::signals::requested() => return Ok(None),
        None => bail!(
            "stopped after {:.0} s without an answer",
            limit.as_secs_f64()
        ),
    };
    if crate::signals::requested() {
        // Ctrl-C reaches the program too: whatever it printed, the sweep stops.
        return Ok(None);
    }
    let (out, err) = (collected(out)?, collected(err)?);
    if !status.success() {
        bail!("it failed ({status}): {}", err.trim());
    }
    let last = out.lines().last().unwrap_or("");
    let printed: Printed = serde_json::from_str(last).with_context(|| {
        format!(
            "it printed '{last}', not the plain loop's {{\"n\",\"steps\",\"wall_s\",\"checksum\"}}"
        )
    })?;
    if printed.n != group.n || printed.steps != group.steps {
        bail!(
            "it ran N = {}, {} steps when asked for N = {}, {} steps",
            printed.n,
            printed.steps,
            group.n,
            group.steps
        );
    }
    if !(printed.wall_s.is_finite() && printed.wall_s > 0.0) {
        bail!("it printed the time {}", printed.wall_s);
    }
    Ok(Some(printed))
}

/// Waits for `child` to end within `limit`: its status, or `None` when the limit passed or a
/// signal asked the sweep to stop first.
fn wait_within(child: &mut Child, limit: Duration) -> anyhow::Result<Option<ExitStatus>> {
    let began = Instant::now();
    loop {
        if let Some(status) = child.try_wait()? {
            return Ok(Some(status));
        }
        if began.elapsed() > limit || crate::signals::requested() {
            return Ok(None);
        }
        std::thread::sleep(Duration::from_millis(5));
    }
}

/// How long a pipe may stay open after its program ended (a program it started may hold it).
const PIPE_GRACE: Duration = Duration::from_secs(5);

/// Reads `pipe` to its end on a thread of its own; the text arrives on the receiver.
fn drain(pipe: Option<impl Read + Send + 'static>) -> mpsc::Receiver<std::io::Result<String>> {
    let (send, receive) = mpsc::channel();
    if let Some(mut pipe) = pipe {
        std::thread::spawn(move || {
            let mut text = String::new();
            let read = pipe.read_to_string(&mut text).map(|_| text);
            let _ = send.send(read);
        });
    } else {
        let _ = send.send(Ok(String::new()));
    }
    receive
}

/// The text [`drain`] read, once its program has ended.
fn collected(text: mpsc::Receiver<std::io::Result<String>>) -> anyhow::Result<String> {
    match text.recv_timeout(PIPE_GRACE) {
        Ok(read) => Ok(read.context("cannot read its output")?),
        Err(_) => bail!(
            "its output stayed open {} s after it ended (a program it started holds it?)",
            PIPE_GRACE.as_secs()
        ),
    }
}
