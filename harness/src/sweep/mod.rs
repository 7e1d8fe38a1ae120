//! `bench-sph sweep`: the cores × chunks study, measured so that its numbers hold up.
//!
//! The pipeline, one module per step: the command line (`bench_sph::cli`) becomes
//! [`params::SweepParams`] (lists expanded by [`range`]); [`plan`] turns them into groups of
//! cells; [`schedule`] orders each group's runs in shuffled rounds; [`runner`] measures them
//! (the reference run, the checksum guard, [`windows`] of contention, the wait for a quiet
//! machine, progress, Ctrl-C) and, after the grid, the cells [`confirm`] chooses; [`rows`]
//! turns a run into its row and [`crate::results::summarize`] a phase's rows into summary
//! rows (paired speedups, intervals from [`crate::results::intervals`]);
//! [`crate::results::export`] writes `trials.csv` and `summary.csv` as runs finish, and
//! `meta.json` records the sessions (the directory itself: [`crate::results::dir`]);
//! [`resume`] continues an interrupted sweep; [`console`] formats what is printed. The CLI
//! then draws the report into the directory (`bench_sph::cli::sweep::run`).
//!
//! What a results directory holds, and how it is read back, is [`crate::results`].

pub mod anchor;
pub mod beside;
pub mod confirm;
pub mod console;
#[cfg(test)]
mod coverage;
pub mod input;
pub mod params;
pub mod plan;
pub mod range;
pub mod resume;
pub mod rows;
pub mod runner;
pub mod schedule;
pub mod timing;
pub mod windows;

use std::collections::{HashMap, HashSet};
use std::fs::{File, OpenOptions};
use std::io::BufWriter;
use std::path::{Path, PathBuf};
use std::time::Duration;

use anyhow::{Context, bail};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

use crate::output::console::plural;
use crate::output::lock::DirLock;
use crate::output::record::Command;
use crate::results::dir as results_dir;
use crate::results::export::Exporter;
use crate::results::key::{Cell, Group};
use crate::results::meta::{Machine, Meta, Session, SweepStatus};
use crate::results::rows::{Phase, Status, SummaryRow, TrialRow};
use crate::results::shard::Shard;
use params::SweepParams;
use plan::LabelStyle;
pub use plan::Plan;
use range::{Axis, compact};
use runner::{Kept, Runner};
use schedule::Schedule;
use timing::Timing;

use crate::contention::Threshold;

pub use crate::results::{META_FILE, SUMMARY_FILE, TRIALS_FILE};

/// Where a sweep writes.
#[derive(Debug, Clone)]
pub enum Target {
    /// A new sweep.
    New {
        /// Its parameters (boxed: they are most of the request's size).
        params: Box<SweepParams>,
        /// The results directory (default `results/<UTC timestamp>`).
        out: Option<PathBuf>,
        /// Replace the results files of an existing directory.
        force: bool,
    },
    /// Continue the sweep in this directory with the parameters of its `meta.json`.
    Resume {
        /// The results directory.
        dir: PathBuf,
    },
}

/// One invocation of `bench-sph sweep`.
#[derive(Debug, Clone)]
pub struct Request {
    /// New sweep or resume.
    pub target: Target,
    /// With `--resume`: measure again every group that has a contended cell.
    pub remeasure_contended: bool,
    /// Longest wait for a quiet machine before each round, seconds (`--wait-quiet`; 0: do not
    /// wait). A setting of the session, not of the plan: a resumed sweep may wait or not.
    pub wait_quiet_s: u64,
    /// Test only: stop as if Ctrl-C was pressed once this many runs are written.
    pub stop_after_runs: Option<usize>,
    /// The command line, program name first (recorded in `meta.json`).
    pub command_line: Vec<String>,
}

/// A results directory ready for cells.
struct Opened {
    dir: PathBuf,
    meta: Meta,
    /// Summary rows of cells finished by earlier sessions.
    finished: Vec<SummaryRow>,
    /// Runs of unfinished phases that earlier sessions measured.
    pending: Vec<TrialRow>,
    /// Whether the CSV files are new (and need their header lines).
    fresh: bool,
    /// The directory's lock, held until the sweep ends.
    lock: DirLock,
}

/// A sweep that has run (to the end or not): its files are complete and its directory still
/// locked, so that the caller can draw the report into it before anyone else writes there.
#[derive(Debug)]
pub struct Finished {
    dir: PathBuf,
    plan: Plan,
    /// Every finished cell's row, from every session.
    rows: Vec<SummaryRow>,
    status: SweepStatus,
    shard: Option<Shard>,
    /// Whether its runs were ordered in rounds (then the first run of each round is checked).
    schedule: Schedule,
    _lock: DirLock,
}

/// How long the busy-machine check before the plan watches the machine.
const BUSY_CHECK: Duration = Duration::from_millis(300);

/// Runs a sweep: plan, measure, write. Returns the finished sweep, whose
/// [`outcome`](Finished::outcome) is the error to end with when it was interrupted or a cell
/// failed; errors here are those that stop it before or while it measures.
// Over ~60 lines on purpose: the sweep's steps in the order they print (open, plan, busy check,
// estimate, measure, conclude), each a call; what is left is handing values between them.
pub fn run(request: Request) -> anyhow::Result<Finished> {
    // From the start: Ctrl-C, SIGTERM or SIGHUP during the plan or the estimate also ends the
    // sweep as interrupted (after the estimate), never as a killed "running" one.
    crate::signals::install(crate::signals::Stop::BetweenRuns);
    let machine = Machine::detect();
    let hardware_threads = machine.hardware_threads;
    let session = Session::start(request.command_line.clone(), machine);
    let mut opened = match &request.target {
        Target::New { params, out, force } => {
            // A placement the operating system refuses stops a new sweep before its directory
            // is made.
            check_placements(params)?;
            start_new(params, out.as_deref(), *force, session)?
        }
        Target::Resume { dir } => reopen(dir, session, request.remeasure_contended)?,
    };
    let params = opened.meta.params.clone();
    if let Some(path) = params.simd {
        // A resumed sweep measures on the path its first cells did.
        if let Some(asked) = sph_solver::simd::chosen().filter(|&asked| asked != path) {
            anyhow::bail!(
                "--simd {asked}: this sweep was measured on {path}; resume it with --simd {path} \
                 or without --simd"
            );
        }
        sph_solver::simd::choose(path).context("cannot resume this sweep here")?;
    }
    let timing = Timing::new(
        params.fake_timings.as_deref(),
        params.fake_contention.as_deref(),
    )?;
    // A resumed sweep's placements, on this machine.
    check_placements(&params)?;
    let plan = Plan::new(&params);
    let threshold = Threshold {
        hardware_threads,
        hz: crate::contention::ticks_per_second(),
    };
    let left = runs_left(&plan, &params, &opened.finished, &opened.pending);

    // Say what will happen before anything slow: the plan, the machine's load, then the
    // estimate (from short, bounded seq runs).
    print_plan(&opened.dir, &params, &plan, &left, hardware_threads);
    if params.pass_cost {
        print("  then: what a pass costs each strategy at each core count (--pass-cost)");
    }
    if let Some(path) = &params.anchor {
        print(&format!(
            "  then: the OpenMP anchor '{}' at each core count, {} (--anchor)",
            path.display(),
            plural(params.trials, "round", "rounds")
        ));
    }
    if request.wait_quiet_s > 0 {
        print(&format!(
            "  before each round, waits up to {} for a quiet machine (--wait-quiet)",
            console::duration(request.wait_quiet_s as f64)
        ));
    }
    let widest = plan.cells.iter().map(|c| c.cores).max().unwrap_or(1);
    let busy = busy_before(&timing, &threshold, widest);
    if let Some(session) = opened.meta.sessions.last_mut() {
        session.busy_threads_at_start = busy.map(|b| b.threads);
    }
    opened.meta.write(&opened.dir.join(META_FILE))?;
    if let Some(b) = busy.filter(|b| b.contended) {
        console_warn(&console::busy_warning(b.threads, hardware_threads));
    }
    let run_ms = run_ms(&estimate(&plan, &left, &params, hardware_threads)?);

    let exporter = Exporter::new(
        append(&opened.dir.join(TRIALS_FILE))?,
        append(&opened.dir.join(SUMMARY_FILE))?,
        opened.fresh,
    )
    .context("cannot write the results")?;
    let total_ms = left
        .runs
        .iter()
        .enumerate()
        .map(|(i, &k)| run_ms[i].saturating_mul(k as u64))
        .fold(0u64, u64::saturating_add);
    let mut runner = Runner {
        plan: &plan,
        params: &params,
        hardware_threads,
        threshold,
        timing,
        stop_after_runs: request.stop_after_runs,
        wait_quiet: Duration::from_secs(request.wait_quiet_s),
        exporter,
        progress: progress_bar(total_ms),
        run_ms,
        runs_written: 0,
    };
    let kept = Kept {
        finished: opened.finished.clone(),
        pending: std::mem::take(&mut opened.pending),
    };
    let outcome = runner.run(&kept);
    runner.progress.finish_and_clear();
    let outcome = outcome?;
    // Pass costs and the anchor, once every cell is measured. Where they stop or fail, the
    // sweep ends as interrupted (its cells kept), so that `--resume` measures them.
    let measured: Vec<&SummaryRow> = opened.finished.iter().chain(&outcome.rows).collect();
    let grid = measured.iter().filter(|r| r.phase == Phase::Grid).count();
    let beside = if !outcome.interrupted && grid >= plan.cells.len() {
        beside::measure(&opened.dir, &plan, &params, &measured, hardware_threads)
    } else {
        Ok(true)
    };
    let interrupted = outcome.interrupted || !matches!(beside, Ok(true));
    let finished = conclude(opened, plan, outcome.rows, interrupted)?;
    beside.map_err(|e| {
        anyhow::anyhow!(
            "{e:#}; the cells are kept: fix it and continue with --resume {}",
            finished.dir.display()
        )
    })?;
    Ok(finished)
}

/// The runs a sweep has left: per plan position, the timed runs still to do (the grid's, plus
/// the most the confirmation could ask for), and the phases already finished.
#[derive(Debug, Clone, PartialEq)]
struct Left {
    /// Timed runs left per cell of the plan.
    runs: Vec<usize>,
    /// Cell phases finished by earlier sessions.
    finished: usize,
}

/// What is left of the plan, given the finished summary rows and pending runs (the
/// confirmation's cells counted at their most, [`confirm::most_chosen`], spread over the
/// group's `seq` cell for the estimate).
fn runs_left(
    plan: &Plan,
    params: &SweepParams,
    finished: &[SummaryRow],
    pending: &[TrialRow],
) -> Left {
    let mut runs = vec![0usize; plan.cells.len()];
    for (i, cell) in plan.cells.iter().enumerate() {
        let done = |phase: Phase| {
            finished
                .iter()
                .any(|r| r.key() == *cell && r.phase == phase)
        };
        if !done(Phase::Grid) {
            let measured = pending
                .iter()
                .filter(|t| t.key() == *cell && t.phase == Phase::Grid)
                .count();
            runs[i] += params.trials.saturating_sub(measured);
        }
    }
    if params.confirm_rounds > 0 && params.shard.is_none() {
        for group in &plan.groups {
            let confirmed = finished
                .iter()
                .any(|r| r.group() == *group && r.phase == Phase::Confirm);
            if confirmed {
                continue;
            }
            if let Some(seq) = plan.cells.iter().position(|c| c.group == *group) {
                runs[seq] += confirm::most_chosen(plan, group) * params.confirm_rounds;
            }
        }
    }
    Left {
        runs,
        finished: finished.len(),
    }
}

/// Refuses, before anything runs, a placement of `params.pin` that the operating system
/// refuses (see [`crate::placement`]).
fn check_placements(params: &SweepParams) -> anyhow::Result<()> {
    for &pin in &params.pin {
        crate::placement::placement(pin).context("cannot place the sweep's threads")?;
    }
    Ok(())
}

/// Estimated milliseconds of one run of each cell (at least 1), from [`estimate`]'s seconds.
fn run_ms(run_s: &[f64]) -> Vec<u64> {
    run_s
        .iter()
        .map(|s| {
            if s.is_finite() {
                (s * 1000.0).ceil().max(1.0) as u64
            } else {
                1
            }
        })
        .collect()
}

/// Records the session's end in `meta.json` and warns about contended cells.
fn conclude(
    mut opened: Opened,
    plan: Plan,
    new_rows: Vec<SummaryRow>,
    interrupted: bool,
) -> anyhow::Result<Finished> {
    let cells_run = new_rows.len();
    let mut rows = std::mem::take(&mut opened.finished);
    rows.extend(new_rows);
    let grid_rows = rows.iter().filter(|r| r.phase == Phase::Grid).count();
    let status = if interrupted || grid_rows < plan.cells.len() {
        SweepStatus::Interrupted
    } else {
        SweepStatus::Complete
    };
    opened.meta.finish(status, cells_run);
    opened.meta.write(&opened.dir.join(META_FILE))?;
    if let Some(contended) = console::contended_cells(&opened.dir, &rows) {
        console_warn(&contended);
    }
    Ok(Finished {
        dir: opened.dir,
        plan,
        rows,
        status,
        shard: opened.meta.params.shard,
        schedule: opened.meta.params.schedule,
        _lock: opened.lock,
    })
}

impl Finished {
    /// The results directory.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// The shard of a plan this sweep ran, if it ran one.
    pub fn shard(&self) -> Option<Shard> {
        self.shard
    }

    /// Whether every planned phase is finished (the report is drawn only then).
    pub fn is_complete(&self) -> bool {
        self.status == SweepStatus::Complete
    }

    /// What it found: the fastest cell of each strategy in each group, after a blank line.
    /// Under rounds, it ends with the check that a round's first run is not systematically
    /// slower than the same cell's other runs (a warm-up that falls short).
    pub fn best_text(&self) -> String {
        let mut text = format!("\n{}", console::best_cells(&self.plan, &self.rows));
        if self.schedule == Schedule::Rounds {
            let trials = crate::results::load::read_trials(&self.dir.join(TRIALS_FILE));
            let effect = trials
                .ok()
                .and_then(|(t, _)| crate::results::summarize::first_run_effect(&t));
            if let Some(line) = effect.map(console::first_run_line) {
                text.push_str(&line);
                text.push('\n');
            }
        }
        text
    }

    /// Where everything is.
    pub fn paths_text(&self) -> String {
        paths_text(&self.dir, &self.rows)
    }

    /// The error that says why the sweep is not complete, or not all ok; `Ok` when it is.
    /// Consumes the sweep, releasing its directory's lock.
    pub fn outcome(self) -> anyhow::Result<()> {
        let (dir, rows, planned) = (&self.dir, &self.rows, self.plan.cells.len());
        if self.status == SweepStatus::Interrupted {
            let grid = rows.iter().filter(|r| r.phase == Phase::Grid).count();
            bail!(
                "interrupted: {grid} of {planned} cells are finished, and every run measured \
                 is saved in '{}'; continue with `bench-sph sweep --resume {}`",
                dir.display(),
                dir.display()
            );
        }
        let failed: Vec<&SummaryRow> = rows.iter().filter(|r| r.status == Status::Failed).collect();
        if let Some(first) = failed.first() {
            bail!(
                "{} of {} cells failed (status=failed in {}); the first: {} at {} cores: {}",
                failed.len(),
                planned,
                dir.join(SUMMARY_FILE).display(),
                first.strategy,
                first.cores,
                first.reason
            );
        }
        Ok(())
    }
}

/// Refuses, before anything is allocated, a group too large for the machine's memory: a run
/// needs [`memory::estimate`] bytes, and the sweep keeps one more copy of the group's
/// initial state (its positions and velocities: 4 f64 per particle) to start every run from.
fn check_memory(plan: &Plan) -> anyhow::Result<()> {
    use sph_solver::scene::memory;
    let available = memory::available_for_run();
    for g in &plan.groups {
        let copy = (g.n as u64).saturating_mul(4 * 8);
        memory::check(
            g.preset,
            g.neighbors,
            g.n,
            available.map(|a| a.saturating_sub(copy)),
        )
        .with_context(|| format!("the group {} cannot run here", g.label(LabelStyle::Sweep)))?;
    }
    Ok(())
}

/// What the check before the plan saw.
#[derive(Debug, Clone, Copy)]
struct Busy {
    /// Hardware threads' worth of CPU that other work used.
    threads: f64,
    /// Whether that is beyond the contention threshold.
    contended: bool,
}

/// Watches the machine for [`BUSY_CHECK`] (or takes `--fake-contention`'s first share), and
/// judges it for the widest cell of the plan (`cores`).
fn busy_before(timing: &Timing, threshold: &Threshold, cores: usize) -> Option<Busy> {
    let (foreign_s, wall_s) = match timing.fake_busy_threads(threshold.hardware_threads) {
        Some(threads) => (threads * BUSY_CHECK.as_secs_f64(), BUSY_CHECK.as_secs_f64()),
        None => crate::clock::sample_now(BUSY_CHECK)?,
    };
    Some(Busy {
        threads: foreign_s / wall_s,
        contended: threshold.exceeded(foreign_s, wall_s, cores),
    })
}

/// Estimated seconds of one run of each cell, from a bounded `seq` run per group that still
/// has cells to run; printed as the plan's last line.
fn estimate(
    plan: &Plan,
    left: &Left,
    params: &SweepParams,
    hardware_threads: usize,
) -> anyhow::Result<Vec<f64>> {
    let groups: Vec<Group> = plan
        .groups
        .iter()
        .copied()
        .filter(|g| (0..plan.cells.len()).any(|i| left.runs[i] > 0 && plan.cells[i].group == *g))
        .collect();
    if !groups.is_empty() {
        let _ = crate::output::console::line("  estimating the time (a short seq run per group)…");
    }
    let seq_run_s: HashMap<Group, f64> = groups
        .iter()
        .map(|&g| (g, input::calibrate(g, params.seed)))
        .collect();
    let run_s: Vec<f64> = plan
        .cells
        .iter()
        .map(|c| {
            let seq = seq_run_s.get(&c.group).copied().unwrap_or(0.0);
            plan::estimate_run_s(c, seq, hardware_threads)
        })
        .collect();
    // The timed runs, plus the warm-ups: each phase's reference runs under rounds, each
    // cell's under cells.
    let warmups = match params.schedule {
        Schedule::Rounds => 0.0,
        Schedule::Cells => params.warmup as f64,
    };
    let reference_runs = groups.len() as f64 * (params.warmup.max(1) + 1) as f64;
    let seq_mean = groups.iter().map(|g| seq_run_s[g]).sum::<f64>() / groups.len().max(1) as f64;
    let total: f64 = (0..plan.cells.len())
        .filter(|&i| left.runs[i] > 0)
        .map(|i| run_s[i] * (left.runs[i] as f64 + warmups))
        .sum::<f64>()
        + reference_runs * seq_mean;
    let mut text = String::new();
    for g in &groups {
        text.push_str(&format!(
            "  seq ≈ {} per run: {}\n",
            console::duration(seq_run_s[g]),
            g.label(LabelStyle::Sweep)
        ));
    }
    text.push_str(&format!(
        "  estimated time: at most about {} (assuming ideal speedup up to {} hardware threads \
         and the largest confirmation; the progress bar's ETA corrects it)\n",
        console::duration(total),
        hardware_threads
    ));
    print(&text);
    Ok(run_s)
}

/// Prints `text`. A closed standard output is not an error here: the runner sees it
/// ([`runner::interrupted`]) and ends the sweep as after Ctrl-C, with `meta.json` saying so.
fn print(text: &str) {
    let _ = crate::output::console::line(text.trim_end_matches('\n'));
}

fn console_warn(text: &str) {
    crate::output::console::warn(text);
}

/// Creates (or, with `force`, reclaims) the directory of a new sweep, locks it and writes its
/// `meta.json`: any problem with the path shows here, before anything runs.
fn start_new(
    params: &SweepParams,
    out: Option<&Path>,
    force: bool,
    session: Session,
) -> anyhow::Result<Opened> {
    params.validate()?;
    check_memory(&Plan::new(params))?;
    let dir = match out {
        Some(dir) => dir.to_path_buf(),
        None => results_dir::new_default()?,
    };
    let mut beside = Vec::new();
    if params.pass_cost {
        beside.push(crate::results::PASS_COST_FILE);
    }
    if params.anchor.is_some() {
        beside.push(crate::results::ANCHOR_FILE);
    }
    let mut claimed = results_dir::open_new(&dir, force, Command::Sweep, &beside)?;
    claimed.record(&[&[TRIALS_FILE, SUMMARY_FILE, META_FILE][..], &beside].concat())?;
    let lock = claimed.lock();
    let plan = Plan::new(params);
    let meta = Meta::new(params.clone(), plan.cells.len(), session);
    meta.write(&dir.join(META_FILE))?;
    Ok(Opened {
        dir,
        meta,
        finished: Vec::new(),
        pending: Vec::new(),
        fresh: true,
        lock,
    })
}

/// Reads an earlier sweep's parameters (checked as the command line checks them), finished
/// cells and runs of unfinished rounds (each re-checked), repairs its CSV files (with
/// `remeasure`, without the rows of every group that has a contended cell), and records this
/// session in its `meta.json`.
fn reopen(dir: &Path, session: Session, remeasure: bool) -> anyhow::Result<Opened> {
    let lock = results_dir::open_existing(dir)?;
    let meta_path = dir.join(META_FILE);
    let mut meta = Meta::read(&meta_path)?;
    if meta.merge.is_some() {
        bail!(
            "'{}' is a merge of shards, not a sweep to resume: resume or run the shards that \
             are missing (`bench-sph sweep --resume SHARD_DIR`) and merge again",
            dir.display()
        );
    }
    meta.params.validate().with_context(|| {
        format!(
            "cannot resume '{}': its {META_FILE} has parameters the command line would refuse",
            dir.display()
        )
    })?;
    let plan = Plan::new(&meta.params);
    check_memory(&plan)?;
    let planned: HashSet<Cell> = plan.cells.iter().copied().collect();
    let params = &meta.params;
    let rounds = |phase: Phase| match phase {
        Phase::Grid => params.trials,
        Phase::Confirm if params.shard.is_none() => params.confirm_rounds,
        Phase::Confirm => 0,
    };
    let check_cell = |row: &SummaryRow| -> Result<(), String> {
        if !planned.contains(&row.key()) || rounds(row.phase) == 0 {
            return Err("not a cell of this sweep's plan".to_owned());
        }
        // A failed cell is finished whatever number of rounds it got to.
        let want = rounds(row.phase);
        if row.status == Status::Ok && row.trials != want {
            return Err(format!(
                "{} rounds, but the sweep's {} phase has {want}",
                row.trials,
                row.phase.as_str()
            ));
        }
        Ok(())
    };
    let check_run = |row: &TrialRow| -> Result<(), String> {
        if !planned.contains(&row.key()) {
            return Err("not a cell of this sweep's plan".to_owned());
        }
        match (row.round, row.position) {
            (Some(r), Some(_)) if (1..=rounds(row.phase)).contains(&r) => Ok(()),
            _ => Err(format!(
                "not a round of the sweep's {} phase",
                row.phase.as_str()
            )),
        }
    };
    let mut repaired = resume::load_and_repair(dir, &check_cell, &check_run)?;
    warn_if_changed(&meta, &session);
    for why in &repaired.rejected {
        console_warn(&format!("warning: dropped, will run again: {why}"));
    }
    if remeasure {
        let contended: HashSet<Group> = repaired
            .finished
            .iter()
            .filter(|r| r.contended == Some(true))
            .map(SummaryRow::group)
            .chain(
                repaired
                    .pending
                    .iter()
                    .filter(|t| t.contended == Some(true))
                    .map(TrialRow::group),
            )
            .collect();
        let removed = repaired.without_groups(&contended, None);
        resume::write_back(dir, &repaired)?;
        print(&format!(
            "--remeasure-contended: {} with contended cells will be measured again from their \
             first round ({removed} rows removed)",
            plural(contended.len(), "group", "groups")
        ));
    }
    // A confirmation chose its cells from its group's grid rows: where the grid runs again,
    // so does the confirmation.
    let regrid: HashSet<Group> = plan
        .cells
        .iter()
        .filter(|c| {
            !repaired
                .finished
                .iter()
                .any(|r| r.key() == **c && r.phase == Phase::Grid)
        })
        .map(|c| c.group)
        .collect();
    if repaired.without_groups(&regrid, Some(Phase::Confirm)) > 0 {
        resume::write_back(dir, &repaired)?;
    }
    print(&format!(
        "Resuming '{}': {} and {} kept{}",
        dir.display(),
        plural(repaired.finished.len(), "finished cell", "finished cells"),
        plural(
            repaired.pending.len(),
            "run of unfinished rounds",
            "runs of unfinished rounds"
        ),
        match repaired.dropped_trial_rows + repaired.dropped_summary_rows {
            0 => String::new(),
            k => format!(" ({k} cut-off, repeated or rejected rows dropped)"),
        }
    ));
    meta.sessions.push(session);
    meta.status = SweepStatus::Running;
    meta.finished_utc = None;
    meta.write(&meta_path)?;
    Ok(Opened {
        dir: dir.to_path_buf(),
        meta,
        finished: repaired.finished,
        pending: repaired.pending,
        fresh: false,
        lock,
    })
}

/// Warns when a resumed sweep continues on another machine or with another build.
fn warn_if_changed(meta: &Meta, session: &Session) {
    let (was, now) = (&meta.machine, &session.machine);
    if !was.same_hardware(now) {
        console_warn(&format!(
            "warning: this sweep started on '{}' ({} hardware threads) and continues on '{}' \
             ({}): times from the two machines are not comparable",
            was.cpu_model, was.hardware_threads, now.cpu_model, now.hardware_threads
        ));
    }
    if meta.git_commit != session.git_commit {
        console_warn(&format!(
            "warning: this sweep started with bench-sph {} and continues with {}",
            meta.git_commit, session.git_commit
        ));
    }
}

/// Opens `path` for appending (creating it).
fn append(path: &Path) -> anyhow::Result<BufWriter<File>> {
    let file = OpenOptions::new()
        .create(true)
        .append(true)
        .open(path)
        .with_context(|| format!("cannot write '{}'", path.display()))?;
    Ok(BufWriter::new(file))
}

/// The plan: groups, strategies, lists, cells and runs; warnings on standard error.
fn print_plan(dir: &Path, params: &SweepParams, plan: &Plan, left: &Left, hardware_threads: usize) {
    let mut text = format!("bench-sph sweep → {}\n", dir.display());
    for group in &plan.groups {
        text.push_str(&format!("  group: {}\n", group.label(LabelStyle::Sweep)));
    }
    if let Some(shard) = params.shard {
        text.push_str(&format!(
            "  shard {shard} of plan {}: {} of its {} (the seq cell of each group here is \
             measured by every shard that has the group)\n",
            params.fingerprint(),
            plural(plan.cells.len(), "cell", "cells"),
            plural(Plan::whole(params).cells.len(), "cell", "cells"),
        ));
    }
    let names: Vec<&str> = params.strategies.iter().map(|s| s.as_str()).collect();
    text.push_str(&format!(
        "  strategies: {} (seq at 1 core is measured in every group: it is the reference)\n",
        names.join(", ")
    ));
    text.push_str(&format!(
        "  cores {}; chunks {} (for {})\n",
        compact(&params.cores, Axis::Cores),
        compact(&params.chunks, Axis::Chunks),
        chunked_strategies(params)
    ));
    text.push_str(&schedule_text(params, plan));
    let to_run: usize = left.runs.iter().sum();
    if left.finished > 0 || to_run < plan.cells.len() * params.trials {
        text.push_str(&format!(
            "  {} finished by earlier sessions; at most {} to run\n",
            plural(left.finished, "cell phase", "cell phases"),
            plural(to_run, "timed run", "timed runs"),
        ));
    }
    print(&text);
    if let Some(note) = console::resolution_note(params) {
        console_warn(&note);
    }
    if let Some(note) = console::placement_note(params, crate::placement::machine_topology()) {
        print(&note);
    }
    if let Some(warning) = console::oversubscription_warning(plan, hardware_threads) {
        console_warn(&warning);
    }
    if params.fake_timings.is_some() || params.fake_contention.is_some() {
        console_warn(
            "warning: --fake-timings/--fake-contention is set (test only): the numbers written \
             are not measurements",
        );
    }
}

/// How the runs are ordered, in two lines of the plan.
fn schedule_text(params: &SweepParams, plan: &Plan) -> String {
    let cells = plural(plan.cells.len(), "cell", "cells");
    let mut text = match params.schedule {
        Schedule::Rounds => format!(
            "  {cells} × {}: in each round every cell of a group runs once, in an order \
             shuffled from --seed {} ({} untimed seq {} first)\n",
            plural(params.trials, "round", "rounds"),
            params.seed,
            params.warmup.max(1),
            if params.warmup > 1 { "runs" } else { "run" },
        ),
        Schedule::Cells => format!(
            "  {cells} × ({} + {}), each cell's runs back to back (--schedule cells)\n",
            plural(params.warmup, "warm-up", "warm-ups"),
            plural(params.trials, "trial", "trials"),
        ),
    };
    if params.confirm_rounds > 0 && params.shard.is_none() {
        text.push_str(&format!(
            "  then, per group, each strategy's best cell per core count (and runner-up, with \
             chunks) again in {} of their own: the findings rest on those\n",
            plural(params.confirm_rounds, "round", "rounds")
        ));
    }
    text
}

fn chunked_strategies(params: &SweepParams) -> String {
    let names: Vec<&str> = params
        .strategies
        .iter()
        .filter(|s| s.info().uses_chunks())
        .map(|s| s.as_str())
        .collect();
    if names.is_empty() {
        "no strategy asked for".to_owned()
    } else {
        names.join(", ")
    }
}

/// A progress bar on standard error (hidden when that is not a terminal), measured in
/// estimated milliseconds so its ETA weighs slow and fast cells properly.
fn progress_bar(total_ms: u64) -> ProgressBar {
    let bar = ProgressBar::with_draw_target(Some(total_ms), ProgressDrawTarget::stderr());
    let style = ProgressStyle::with_template(
        "{elapsed_precise} [{wide_bar}] {percent:>3}%  ETA {eta}  {msg}",
    )
    .expect("the template is valid")
    .progress_chars("=> ");
    bar.set_style(style);
    bar
}

/// Where everything is.
fn paths_text(dir: &Path, rows: &[SummaryRow]) -> String {
    let trial_rows: usize = rows.iter().map(|r| r.trials).sum();
    let failed = rows.iter().filter(|r| r.status == Status::Failed).count();
    let mut text = format!("Results in {}:\n", dir.display());
    text.push_str(&format!(
        "  {:<40} {}\n",
        dir.join(TRIALS_FILE).display().to_string(),
        plural(trial_rows, "trial row", "trial rows")
    ));
    text.push_str(&format!(
        "  {:<40} {}{}\n",
        dir.join(SUMMARY_FILE).display().to_string(),
        plural(rows.len(), "cell", "cells"),
        if failed > 0 {
            format!(", {failed} failed")
        } else {
            String::new()
        }
    ));
    text.push_str(&format!(
        "  {:<40} machine, build, command lines, parameters\n",
        dir.join(META_FILE).display().to_string()
    ));
    for (name, what) in [
        (
            crate::results::PASS_COST_FILE,
            "what a pass costs each strategy (--pass-cost)",
        ),
        (
            crate::results::ANCHOR_FILE,
            "the OpenMP anchor's runs (--anchor)",
        ),
    ] {
        if dir.join(name).is_file() {
            text.push_str(&format!(
                "  {:<40} {what}\n",
                dir.join(name).display().to_string()
            ));
        }
    }
    text
}
