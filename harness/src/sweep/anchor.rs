//! `sweep --anchor PATH`: the plain C++ loop's OpenMP build run beside the cells
//! ([`crate::results::anchor`]). After the cells, for each group of the `seed` preset with
//! all-pairs (what the plain loop computes), the program runs as `PATH N STEPS SEED` with
//! `OMP_NUM_THREADS` set to each of the sweep's core counts (and 1, its reference), in
//! `--trials` rounds, each round's thread counts in a shuffled order as the cells' are
//! ([`super::schedule`]). Its time is the one it prints (its steps, without starting the
//! process); its checksum is the group's `seq` checksum when it computed the same state.

use std::io::Read;
use std::path::Path;
use std::process::{Command, Stdio};
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
        let printed = run_once(path, group, t, params.seed, limit)
            .with_context(|| format!("--anchor '{}' on {t} threads", path.display()))?;
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

/// One run of the program: what it printed, checked against what it was asked.
fn run_once(
    path: &Path,
    group: &Group,
    threads: usize,
    seed: u64,
    limit: Duration,
) -> anyhow::Result<Printed> {
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
    let began = Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait()? {
            break status;
        }
        if began.elapsed() > limit || crate::signals::requested() {
            // Best effort: it may have ended in between.
            let _ = child.kill();
            let _ = child.wait();
            bail!(
                "stopped after {:.0} s without an answer",
                limit.as_secs_f64()
            );
        }
        std::thread::sleep(Duration::from_millis(5));
    };
    let mut out = String::new();
    let mut err = String::new();
    if let Some(mut s) = child.stdout.take() {
        s.read_to_string(&mut out)?;
    }
    if let Some(mut s) = child.stderr.take() {
        s.read_to_string(&mut err)?;
    }
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
    Ok(printed)
}
