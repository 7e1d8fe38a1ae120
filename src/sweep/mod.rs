//! `bench-sph sweep`: the cores × chunks study, measured so that its numbers hold up.
//!
//! The pipeline, one module per step: the command line ([`crate::cli`]) becomes
//! [`params::SweepParams`] (lists expanded by [`range`]); [`plan`] turns them into groups of
//! cells; [`runner`] measures each cell (warm-ups, timed trials, the checksum guard, progress,
//! Ctrl-C); [`rows`] and [`stats`] turn measurements into rows; [`export`] writes them to
//! `trials.csv` and `summary.csv` after every cell; [`meta`] writes `meta.json`; [`resume`]
//! continues an interrupted sweep; [`console`] formats what is printed.
//!
//! A results directory holds:
//! - `trials.csv`: one row per timed trial (columns [`export::TRIAL_COLUMNS`]);
//! - `summary.csv`: one row per cell (columns [`export::SUMMARY_COLUMNS`]): mean, sample
//!   stddev, min, median, max of the wall seconds, mean CPU seconds, speedup over the group's
//!   `seq` mean, efficiency = speedup / cores, outliers (|t − median| > 3 MAD),
//!   oversubscribed, the common checksum, status and reason;
//! - `meta.json`: machine, build, times, command lines and every parameter.

pub mod console;
pub mod export;
pub mod meta;
pub mod params;
pub mod plan;
pub mod range;
pub mod resume;
pub mod rows;
pub mod runner;
pub mod stats;
pub mod timing;

use std::collections::{HashMap, HashSet};
use std::fs::{File, OpenOptions};
use std::io::BufWriter;
use std::path::{Path, PathBuf};

use anyhow::{Context, bail};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

use meta::{Machine, Meta, Session, SweepStatus};
use params::SweepParams;
use plan::{CellKey, Group, Plan};
use range::{Axis, compact};
use rows::{Status, SummaryRow};
use runner::{Reference, Runner};
use timing::Timing;

/// The per-trial file.
pub const TRIALS_FILE: &str = "trials.csv";
/// The per-cell file.
pub const SUMMARY_FILE: &str = "summary.csv";
/// The metadata file.
pub const META_FILE: &str = "meta.json";

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
    /// Do not draw charts at the end.
    pub no_plots: bool,
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
    /// Whether the CSV files are new (and need their header lines).
    fresh: bool,
}

/// Runs a sweep: plan, measure, write, summarise. Errors (after writing all that is done)
/// when it was interrupted or a cell failed.
pub fn run(request: Request) -> anyhow::Result<()> {
    let machine = Machine::detect();
    let hardware_threads = machine.hardware_threads;
    let session = Session::start(request.command_line.clone(), machine);
    let Opened {
        dir,
        mut meta,
        finished,
        fresh,
    } = match &request.target {
        Target::New { params, out, force } => start_new(params, out.as_deref(), *force, session)?,
        Target::Resume { dir } => reopen(dir, session)?,
    };
    let params = meta.params.clone();
    let timing = Timing::new(params.fake_timings.as_deref())?;
    let plan = Plan::new(&params);
    let exporter = export::Exporter::new(
        append(&dir.join(TRIALS_FILE))?,
        append(&dir.join(SUMMARY_FILE))?,
        fresh,
    )
    .context("cannot write the results")?;

    let done: HashSet<CellKey> = finished.iter().map(SummaryRow::key).collect();
    let todo: Vec<usize> = (0..plan.cells.len())
        .filter(|&i| !done.contains(&plan.cells[i].key()))
        .collect();
    let mut references: HashMap<Group, Reference> = finished
        .iter()
        .filter(|r| r.strategy == sph_strategies::StrategyName::Seq.as_str())
        .filter_map(|r| {
            let cell = plan.cells.iter().find(|c| c.key() == r.key())?;
            Some((cell.group, Reference::from_row(r)))
        })
        .collect();

    // Calibrate the groups that still have cells, then say what will happen.
    let seq_run_s: HashMap<Group, f64> = plan
        .groups
        .iter()
        .filter(|g| todo.iter().any(|&i| plan.cells[i].group == **g))
        .map(|&g| (g, runner::calibrate(g, params.seed)))
        .collect();
    let runs_per_cell = params.warmup + params.trials;
    let run_s: Vec<f64> = plan
        .cells
        .iter()
        .map(|c| {
            let seq = seq_run_s.get(&c.group).copied().unwrap_or(0.0);
            plan::estimate_run_s(c, seq, hardware_threads)
        })
        .collect();
    let estimate: f64 = todo.iter().map(|&i| run_s[i] * runs_per_cell as f64).sum();
    print_plan(
        &dir,
        &params,
        &plan,
        &todo,
        estimate,
        &seq_run_s,
        hardware_threads,
    );

    runner::install_ctrlc_handler();
    let run_ms: Vec<u64> = run_s
        .iter()
        .map(|s| {
            if s.is_finite() {
                (s * 1000.0).ceil().max(1.0) as u64
            } else {
                1
            }
        })
        .collect();
    let progress = progress_bar(todo.iter().map(|&i| run_ms[i] * runs_per_cell as u64).sum());
    let mut runner = Runner {
        plan: &plan,
        warmup: params.warmup,
        trials: params.trials,
        seed: params.seed,
        hardware_threads,
        timing,
        stop_after_cells: request.stop_after_cells,
        exporter,
        progress: progress.clone(),
        run_ms,
    };
    let outcome = runner.run(&todo, &mut references);
    progress.finish_and_clear();
    let outcome = outcome?;

    let all_rows: Vec<SummaryRow> = finished.iter().chain(&outcome.rows).cloned().collect();
    let complete = all_rows.len() >= plan.cells.len();
    let status = if outcome.interrupted || !complete {
        SweepStatus::Interrupted
    } else {
        SweepStatus::Complete
    };
    meta.finish(status, outcome.rows.len());
    meta.write(&dir.join(META_FILE))?;

    println!();
    print!("{}", console::best_cells(&plan, &all_rows));
    if status == SweepStatus::Complete {
        println!("{}", render_charts(&dir, request.no_plots)?);
    }
    print_paths(&dir, &all_rows);

    if status == SweepStatus::Interrupted {
        bail!(
            "interrupted: {} of {} cells are finished and saved in '{}'; \
             continue with `bench-sph sweep --resume {}`",
            all_rows.len(),
            plan.cells.len(),
            dir.display(),
            dir.display()
        );
    }
    let failed: Vec<&SummaryRow> = all_rows
        .iter()
        .filter(|r| r.status == Status::Failed)
        .collect();
    if let Some(first) = failed.first() {
        bail!(
            "{} of {} cells failed (status=failed in {}); the first: {} at {} cores: {}",
            failed.len(),
            plan.cells.len(),
            dir.join(SUMMARY_FILE).display(),
            first.strategy,
            first.cores,
            first.reason
        );
    }
    Ok(())
}

/// The one place where a finished sweep's charts are made: `bench-sph report` on the sweep's
/// directory, writing into it. A drawing failure is an error, but the CSVs and meta.json are
/// already complete by then.
fn render_charts(dir: &Path, no_plots: bool) -> anyhow::Result<String> {
    if no_plots {
        return Ok("Charts: skipped (--no-plots).".to_owned());
    }
    let written = crate::report::generate(&[dir.to_path_buf()], dir, &[]).with_context(|| {
        format!(
            "the charts and REPORT.md could not be made (the results in '{}' are complete; \
             retry with `bench-sph report {}`)",
            dir.display(),
            dir.display()
        )
    })?;
    let mut text = format!("Charts and report ({} files):", written.len());
    for p in &written {
        text.push_str(&format!("\n  {}", p.display()));
    }
    Ok(text)
}

/// Creates (or, with `force`, reclaims) the directory of a new sweep and writes its
/// `meta.json`: any problem with the path shows here, before anything runs.
fn start_new(
    params: &SweepParams,
    out: Option<&Path>,
    force: bool,
    session: Session,
) -> anyhow::Result<Opened> {
    Timing::new(params.fake_timings.as_deref())?;
    let dir = out.map_or_else(
        || Path::new("results").join(meta::timestamp_dir_name()),
        Path::to_path_buf,
    );
    if dir.exists() {
        if !dir.is_dir() {
            bail!("--out '{}' exists and is not a directory", dir.display());
        }
        let non_empty = std::fs::read_dir(&dir)
            .with_context(|| format!("cannot read results directory '{}'", dir.display()))?
            .next()
            .is_some();
        if non_empty && !force {
            bail!(
                "results directory '{}' already exists and is not empty; continue that sweep \
                 with `--resume {}`, or replace its results with `--force`",
                dir.display(),
                dir.display()
            );
        }
        // --force replaces the files a sweep writes, and only those.
        for name in [TRIALS_FILE, SUMMARY_FILE, META_FILE] {
            let path = dir.join(name);
            if path.exists() {
                std::fs::remove_file(&path)
                    .with_context(|| format!("cannot replace '{}'", path.display()))?;
            }
        }
    } else {
        std::fs::create_dir_all(&dir)
            .with_context(|| format!("cannot create results directory '{}'", dir.display()))?;
    }
    let plan = Plan::new(params);
    let meta = Meta::new(params.clone(), plan.cells.len(), session);
    meta.write(&dir.join(META_FILE))?;
    Ok(Opened {
        dir,
        meta,
        finished: Vec::new(),
        fresh: true,
    })
}

/// Reads an earlier sweep's parameters and finished cells, repairs its CSV files, and
/// records this session in its `meta.json`.
fn reopen(dir: &Path, session: Session) -> anyhow::Result<Opened> {
    let meta_path = dir.join(META_FILE);
    if !meta_path.is_file() {
        bail!(
            "cannot resume '{}': it has no {META_FILE}, so it is not a sweep's results directory",
            dir.display()
        );
    }
    let mut meta = Meta::read(&meta_path)?;
    let repaired = resume::load_and_repair(dir)?;
    let (was, now) = (&meta.machine, &session.machine);
    if was.cpu_model != now.cpu_model || was.hardware_threads != now.hardware_threads {
        eprintln!(
            "warning: this sweep started on '{}' ({} hardware threads) and continues on '{}' \
             ({}): times from the two machines are not comparable",
            was.cpu_model, was.hardware_threads, now.cpu_model, now.hardware_threads
        );
    }
    if meta.git_commit != session.git_commit {
        eprintln!(
            "warning: this sweep started with bench-sph {} and continues with {}",
            meta.git_commit, session.git_commit
        );
    }
    println!(
        "Resuming '{}': {} finished cells kept{}",
        dir.display(),
        repaired.finished.len(),
        match repaired.dropped_trial_rows + repaired.dropped_summary_rows {
            0 => String::new(),
            k => format!(" ({k} rows of an unfinished cell dropped)"),
        }
    );
    meta.sessions.push(session);
    meta.status = SweepStatus::Running;
    meta.finished_utc = None;
    meta.write(&meta_path)?;
    Ok(Opened {
        dir: dir.to_path_buf(),
        meta,
        finished: repaired.finished,
        fresh: false,
    })
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

/// The plan: groups, strategies, lists, cells, runs and the estimated duration; warnings on
/// standard error.
fn print_plan(
    dir: &Path,
    params: &SweepParams,
    plan: &Plan,
    todo: &[usize],
    estimate_s: f64,
    seq_run_s: &HashMap<Group, f64>,
    hardware_threads: usize,
) {
    println!("bench-sph sweep → {}", dir.display());
    for group in &plan.groups {
        let seq = seq_run_s
            .get(group)
            .map(|&s| format!(" (seq ≈ {} per run)", console::duration(s)))
            .unwrap_or_default();
        println!("  group: {}{seq}", group.label());
    }
    let names: Vec<&str> = params.strategies.iter().map(|s| s.as_str()).collect();
    println!(
        "  strategies: {} (seq at 1 core is measured in every group: it is the reference)",
        names.join(", ")
    );
    println!(
        "  cores {}; chunks {} (for {})",
        compact(&params.cores, Axis::Cores),
        compact(&params.chunks, Axis::Chunks),
        chunked_strategies(params)
    );
    println!(
        "  {} × ({} + {}) = {}",
        console::plural(plan.cells.len(), "cell", "cells"),
        console::plural(params.warmup, "warm-up", "warm-ups"),
        console::plural(params.trials, "trial", "trials"),
        console::plural(
            plan.cells.len() * (params.warmup + params.trials),
            "run",
            "runs"
        ),
    );
    if todo.len() < plan.cells.len() {
        println!(
            "  {} already finished, {} to run",
            plan.cells.len() - todo.len(),
            todo.len()
        );
    }
    println!(
        "  estimated time: about {} (from a short seq run per group, assuming ideal speedup up \
         to {} hardware threads; the progress bar's ETA corrects it)",
        console::duration(estimate_s),
        hardware_threads
    );
    if let Some(warning) = console::oversubscription_warning(plan, hardware_threads) {
        eprintln!("{warning}");
    }
    if params.fake_timings.is_some() {
        eprintln!(
            "warning: --fake-timings is set (test only): the times written are not measurements"
        );
    }
    println!();
}

fn chunked_strategies(params: &SweepParams) -> String {
    let names: Vec<&str> = params
        .strategies
        .iter()
        .filter(|s| s.info().uses_chunks)
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
fn print_paths(dir: &Path, rows: &[SummaryRow]) {
    let trial_rows: usize = rows.iter().map(|r| r.trials).sum();
    let failed = rows.iter().filter(|r| r.status == Status::Failed).count();
    println!("Results in {}:", dir.display());
    println!(
        "  {:<40} {}",
        dir.join(TRIALS_FILE).display().to_string(),
        console::plural(trial_rows, "trial row", "trial rows")
    );
    println!(
        "  {:<40} {}{}",
        dir.join(SUMMARY_FILE).display().to_string(),
        console::plural(rows.len(), "cell", "cells"),
        if failed > 0 {
            format!(", {failed} failed")
        } else {
            String::new()
        }
    );
    println!(
        "  {:<40} machine, build, command lines, parameters",
        dir.join(META_FILE).display().to_string()
    );
}
