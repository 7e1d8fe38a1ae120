//! `bench-sph sweep`: the cores × chunks study, measured so that its numbers hold up.
//!
//! The pipeline, one module per step: the command line ([`crate::cli`]) becomes
//! [`params::SweepParams`] (lists expanded by [`range`]); [`plan`] turns them into groups of
//! cells; [`runner`] measures each cell (warm-ups, timed trials, the checksum guard, progress,
//! Ctrl-C); [`rows`] turns measurements into rows (statistics from
//! [`crate::results::stats`], intervals from [`bootstrap`]); [`export`] writes them to
//! `trials.csv` and `summary.csv` after every cell, and `meta.json` records the sessions;
//! [`resume`] continues an interrupted sweep; [`console`] formats what is printed. The CLI
//! then draws the report into the directory (`crate::cli::sweep::run`).
//!
//! What a results directory holds, and how it is read back, is [`crate::results`].

pub mod bootstrap;
pub mod console;
pub mod dir;
pub mod export;
pub mod lock;
pub mod params;
pub mod plan;
pub mod range;
pub mod resume;
pub mod rows;
pub mod runner;
pub mod timing;

use std::collections::{HashMap, HashSet};
use std::fs::{File, OpenOptions};
use std::io::BufWriter;
use std::path::{Path, PathBuf};
use std::time::Duration;

use anyhow::{Context, bail};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

use crate::output::console::plural;
use crate::results::meta::{Machine, Meta, Session, SweepStatus};
use crate::results::rows::{Status, SummaryRow, TrialRow};
use crate::results::shard::Shard;
use lock::DirLock;
use params::SweepParams;
use plan::{Cell, Group, LabelStyle, Plan};
use range::{Axis, compact};
use runner::{Reference, Runner};
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
    /// Test only: stop as if Ctrl-C was pressed once this many cells are written.
    pub stop_after_cells: Option<usize>,
    /// The command line, program name first (recorded in `meta.json`).
    pub command_line: Vec<String>,
}

/// A results directory ready for cells.
struct Opened {
    dir: PathBuf,
    meta: Meta,
    /// Summary rows of cells finished by earlier sessions.
    finished: Vec<SummaryRow>,
    /// Their trial rows.
    finished_trials: Vec<TrialRow>,
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
    // From the start: a Ctrl-C during the plan or the estimate also ends the sweep as
    // interrupted (after the estimate), never as a killed "running" one.
    runner::install_ctrlc_handler();
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
        Target::Resume { dir } => reopen(dir, session)?,
    };
    let params = opened.meta.params.clone();
    if let Some(path) = params.simd {
        // A resumed sweep measures on the path its first cells did.
        if let Some(asked) = crate::simd::chosen().filter(|&asked| asked != path) {
            anyhow::bail!(
                "--simd {asked}: this sweep was measured on {path}; resume it with --simd {path} \
                 or without --simd"
            );
        }
        crate::simd::choose(path).context("cannot resume this sweep here")?;
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
    let done: HashSet<Cell> = opened.finished.iter().map(SummaryRow::key).collect();
    let todo: Vec<usize> = (0..plan.cells.len())
        .filter(|&i| !done.contains(&plan.cells[i]))
        .collect();
    let mut references = finished_references(&plan, &opened.finished, &opened.finished_trials);

    // Say what will happen before anything slow: the plan, the machine's load, then the
    // estimate (from short, bounded seq runs).
    print_plan(&opened.dir, &params, &plan, &todo, hardware_threads);
    let widest = plan.cells.iter().map(|c| c.cores).max().unwrap_or(1);
    let busy = busy_before(&timing, &threshold, widest);
    if let Some(session) = opened.meta.sessions.last_mut() {
        session.busy_threads_at_start = busy.map(|b| b.threads);
    }
    opened.meta.write(&opened.dir.join(META_FILE))?;
    if let Some(b) = busy.filter(|b| b.contended) {
        console_warn(&console::busy_warning(b.threads, hardware_threads));
    }
    let run_ms = run_ms(&estimate(&plan, &todo, &params, hardware_threads)?);

    let exporter = export::Exporter::new(
        append(&opened.dir.join(TRIALS_FILE))?,
        append(&opened.dir.join(SUMMARY_FILE))?,
        opened.fresh,
    )
    .context("cannot write the results")?;
    let runner = Runner {
        plan: &plan,
        warmup: params.warmup,
        trials: params.trials,
        seed: params.seed,
        resamples: bootstrap::RESAMPLES,
        hardware_threads,
        threshold,
        timing,
        stop_after_cells: request.stop_after_cells,
        exporter,
        progress: ProgressBar::hidden(),
        run_ms,
        shard: params.shard.map(|s| s.index),
    };
    let outcome = measure(runner, &todo, &mut references)?;
    conclude(opened, plan, outcome.rows, outcome.interrupted)
}

/// Refuses, before anything runs, a placement of `params.pin` that the operating system
/// refuses (see [`crate::placement`]).
fn check_placements(params: &SweepParams) -> anyhow::Result<()> {
    for &pin in &params.pin {
        crate::placement::placement(pin).context("cannot place the sweep's threads")?;
    }
    Ok(())
}

/// Runs the cells `todo` under a progress bar measured in estimated milliseconds (see
/// [`progress_bar`]), cleared when the runner stops.
fn measure<T: std::io::Write, S: std::io::Write>(
    mut runner: Runner<'_, T, S>,
    todo: &[usize],
    references: &mut HashMap<Group, Reference>,
) -> anyhow::Result<runner::SessionOutcome> {
    let runs_per_cell = (runner.warmup + runner.trials) as u64;
    let total_ms = todo
        .iter()
        .map(|&i| runner.run_ms[i].saturating_mul(runs_per_cell))
        .fold(0u64, u64::saturating_add);
    runner.progress = progress_bar(total_ms);
    let outcome = runner.run(todo, references);
    runner.progress.finish_and_clear();
    outcome
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
    let status = if interrupted || rows.len() < plan.cells.len() {
        SweepStatus::Interrupted
    } else {
        SweepStatus::Complete
    };
    opened.meta.finish(status, cells_run);
    opened.meta.write(&opened.dir.join(META_FILE))?;
    if let Some(contended) = console::contended_cells(&rows) {
        console_warn(&contended);
    }
    Ok(Finished {
        dir: opened.dir,
        plan,
        rows,
        status,
        shard: opened.meta.params.shard,
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

    /// Whether every planned cell is finished (the report is drawn only then).
    pub fn is_complete(&self) -> bool {
        self.status == SweepStatus::Complete
    }

    /// What it found: the fastest cell of each strategy in each group, after a blank line.
    pub fn best_text(&self) -> String {
        format!("\n{}", console::best_cells(&self.plan, &self.rows))
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
            bail!(
                "interrupted: {} of {} cells are finished and saved in '{}'; \
                 continue with `bench-sph sweep --resume {}`",
                rows.len(),
                planned,
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

/// The references of groups whose `seq` cell an earlier session finished.
fn finished_references(
    plan: &Plan,
    finished: &[SummaryRow],
    trials: &[TrialRow],
) -> HashMap<Group, Reference> {
    finished
        .iter()
        .filter(|r| r.key().is_reference())
        .filter_map(|r| {
            let cell = plan.cells.iter().find(|&&c| c == r.key())?;
            let walls = trials
                .iter()
                .filter(|t| t.key() == r.key())
                .map(|t| t.wall_s)
                .collect();
            Some((cell.group, Reference::from_row(r, walls)))
        })
        .collect()
}

/// Refuses, before anything is allocated, a group too large for the machine's memory: a run
/// needs [`memory::estimate`] bytes, and the sweep keeps one more copy of the group's
/// initial state (its positions and velocities: 4 f64 per particle) to start every run from.
fn check_memory(plan: &Plan) -> anyhow::Result<()> {
    use crate::scene::memory;
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
    todo: &[usize],
    params: &SweepParams,
    hardware_threads: usize,
) -> anyhow::Result<Vec<f64>> {
    let groups: Vec<Group> = plan
        .groups
        .iter()
        .copied()
        .filter(|g| todo.iter().any(|&i| plan.cells[i].group == *g))
        .collect();
    if !groups.is_empty() {
        let _ = crate::output::console::line("  estimating the time (a short seq run per group)…");
    }
    let seq_run_s: HashMap<Group, f64> = groups
        .iter()
        .map(|&g| (g, runner::calibrate(g, params.seed)))
        .collect();
    let run_s: Vec<f64> = plan
        .cells
        .iter()
        .map(|c| {
            let seq = seq_run_s.get(&c.group).copied().unwrap_or(0.0);
            plan::estimate_run_s(c, seq, hardware_threads)
        })
        .collect();
    let total: f64 = todo
        .iter()
        .map(|&i| run_s[i] * (params.warmup + params.trials) as f64)
        .sum();
    let mut text = String::new();
    for g in &groups {
        text.push_str(&format!(
            "  seq ≈ {} per run: {}\n",
            console::duration(seq_run_s[g]),
            g.label(LabelStyle::Sweep)
        ));
    }
    text.push_str(&format!(
        "  estimated time: about {} (assuming ideal speedup up to {} hardware threads; the \
         progress bar's ETA corrects it)\n",
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
        None => dir::new_default()?,
    };
    let lock = dir::open_new(&dir, force)?;
    let plan = Plan::new(params);
    let meta = Meta::new(params.clone(), plan.cells.len(), session);
    meta.write(&dir.join(META_FILE))?;
    Ok(Opened {
        dir,
        meta,
        finished: Vec::new(),
        finished_trials: Vec::new(),
        fresh: true,
        lock,
    })
}

/// Reads an earlier sweep's parameters (checked as the command line checks them) and
/// finished cells (each re-checked), repairs its CSV files, and records this session in its
/// `meta.json`.
fn reopen(dir: &Path, session: Session) -> anyhow::Result<Opened> {
    let lock = dir::open_existing(dir)?;
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
    let trials = meta.params.trials;
    let check = |row: &SummaryRow| -> Result<(), String> {
        if !planned.contains(&row.key()) {
            return Err("not a cell of this sweep's plan".to_owned());
        }
        // A failed cell is finished whatever number of trials it got to.
        if row.status == Status::Ok && row.trials != trials {
            return Err(format!(
                "{} trials, but the sweep asks for {trials}",
                row.trials
            ));
        }
        Ok(())
    };
    let repaired = resume::load_and_repair(dir, &check)?;
    warn_if_changed(&meta, &session);
    for why in &repaired.rejected {
        console_warn(&format!("warning: dropped, will run again: {why}"));
    }
    if repaired.upgraded {
        print(&format!(
            "Upgraded '{}': its CSV files were written by an earlier version; the columns it \
             lacked (of reference_shard, pin, smt; passes_alone in trials.csv) are appended, \
             empty (pin empty = none, passes_alone empty = unknown)",
            dir.display()
        ));
    }
    print(&format!(
        "Resuming '{}': {} finished cells kept{}",
        dir.display(),
        repaired.finished.len(),
        match repaired.dropped_trial_rows + repaired.dropped_summary_rows {
            0 => String::new(),
            k => format!(" ({k} rows of unfinished or rejected cells dropped)"),
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
        finished_trials: repaired.finished_trials,
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
fn print_plan(
    dir: &Path,
    params: &SweepParams,
    plan: &Plan,
    todo: &[usize],
    hardware_threads: usize,
) {
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
    text.push_str(&format!(
        "  {} × ({} + {}) = {}\n",
        plural(plan.cells.len(), "cell", "cells"),
        plural(params.warmup, "warm-up", "warm-ups"),
        plural(params.trials, "trial", "trials"),
        plural(
            plan.cells.len() * (params.warmup + params.trials),
            "run",
            "runs"
        ),
    ));
    if todo.len() < plan.cells.len() {
        text.push_str(&format!(
            "  {} already finished, {} to run\n",
            plan.cells.len() - todo.len(),
            todo.len()
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
    text
}
