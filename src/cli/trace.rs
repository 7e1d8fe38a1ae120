//! `bench-sph trace`: a few warmed-up steps with every kernel call recorded; writes
//! trace.json, timeline.png, stats.csv and meta.json into a claimed directory (each file
//! whole or not at all) and prints a summary.

use std::path::PathBuf;

use anyhow::Context;
use clap::Args;
use sph_strategies::Config;

use crate::checksum::checksum_hex;
use crate::output::atomic::AtomicFile;
use crate::output::claim::{self, Claimed, Owner};
use crate::output::console;
use crate::output::record::Command;
use crate::plot::timeline;
use crate::solver::Simulation;
use crate::trace::files::{self, TOOL, TraceMeta};
use crate::trace::size::{self, Plan};
use crate::trace::stats::{self, Stats};
use crate::trace::{TraceConfig, TracedRun, chrome, run_traced, run_untraced};

/// Options of `trace`.
#[derive(Debug, Clone, Args)]
#[command(mut_args(super::parallel::strategy_required(
    "Parallel strategy to trace (see `bench-sph list`)"
)))]
pub struct TraceArgs {
    /// The scene: preset, N, neighbour search, seed, initial state.
    #[command(flatten)]
    pub scene: super::scene::SceneArgs,
    /// How the passes run: strategy, worker threads, chunks.
    #[command(flatten)]
    pub parallel: super::parallel::ParallelArgs,
    /// Number of steps to record.
    #[arg(long, default_value_t = 5, value_parser = super::steps)]
    pub steps: usize,
    /// Untimed, unrecorded steps (on a copy of the initial state, on the same threads) before
    /// the recorded ones, so that every worker is awake (0 to 1000).
    #[arg(long, default_value_t = 5, value_parser = super::warmup)]
    pub warmup: usize,
    /// Output directory (created if missing): trace.json, timeline.png, stats.csv, meta.json.
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// Write into an --out directory that holds files trace did not write, leaving them as
    /// they are (only trace's own files are replaced).
    #[arg(long)]
    pub force: bool,
    /// Draw only the last K steps in timeline.png [default: all steps, at most the last 3].
    #[arg(long, value_name = "K", value_parser = super::steps)]
    pub timeline_steps: Option<usize>,
    /// Also time REPS untraced and REPS traced runs of the same steps, alternately, and print
    /// the minimum and median wall time of each: the cost of tracing. The files then come
    /// from the last traced run.
    #[arg(long, value_name = "REPS", value_parser = super::repetitions)]
    pub compare: Option<usize>,
}

/// Minimum and median of untraced and traced wall times.
struct Comparison {
    untraced: Vec<f64>,
    traced: Vec<f64>,
}

/// Runs `trace`: checks the trace's size and claims `--out` before anything runs, then
/// records, writes every file atomically (a failure leaves the directory as it was) and
/// removes trace's own stale files.
pub fn run(args: &TraceArgs) -> anyhow::Result<()> {
    let scene = args.scene.scene()?;
    if let Some(note) = args.scene.resolution_note() {
        console::warn(&note);
    }
    let strategy_config = args.parallel.config()?;
    let cores = strategy_config.cores;
    Plan {
        strategy: args.parallel.strategy,
        // Every particle, walls included: the longest pass's length bounds its calls.
        n: scene.state.len(),
        chunks: args.parallel.chunks,
        cores,
        steps: args.steps,
        passes: scene.physics.passes().len(),
        neighbors: args.scene.neighbors,
    }
    .check()?;
    // Claimed (and locked) before anything runs, and held until the files are written.
    let (mut claimed, paths) = claim_out(args)?;
    let config = trace_config(args, scene.fluid(), cores);
    let fresh = || scene.clone().simulate(args.scene.neighbors);
    let (sim, run, comparison) = record(args, &strategy_config, fresh)?;

    size::check_recorded(
        args.parallel.strategy,
        run.trace.kernels.len() + run.trace.serial.len(),
    )?;
    let stats = stats::compute(&run.trace);
    let shown = args.timeline_steps.unwrap_or(3).min(args.steps);
    let meta = TraceMeta {
        tool: Some(TOOL.to_owned()),
        config,
        warmup_steps: args.warmup,
        wall_s: run.elapsed.wall_s,
        cpu_s: run.elapsed.cpu_s,
        kernel_calls: stats.total.kernel_calls,
        worker_threads: stats.total.worker_threads,
        workers_used: stats.total.workers_used,
        checksum: checksum_hex(&sim.state),
        timeline_steps: [args.steps + 1 - shown, args.steps],
        simd: sim.simd(),
        pin: args.parallel.pin,
    };
    claimed.record(&FILES)?;
    write_files(&paths, &run, &stats, &meta)?;
    let removed = claimed.remove_stale(&paths)?;

    let mut lines = summary(&meta.config, args.warmup, &stats, run.elapsed.wall_s);
    if args.compare.is_some() {
        let cost_ns = crate::trace::executor::recording_cost_ns(200_000);
        lines.extend(comparison_lines(&comparison, &stats, cost_ns));
    }
    lines.push(format!("wrote {}", list(&paths)));
    if !removed.is_empty() {
        lines.push(format!(
            "removed stale files of an earlier trace: {}",
            list(&removed)
        ));
    }
    print(&lines, &claimed)
}

/// The files of a trace directory, in the order written.
const FILES: [&str; 4] = [
    files::TRACE_JSON,
    files::TIMELINE_PNG,
    files::STATS_CSV,
    files::META_JSON,
];

/// Claims `--out` for the trace and checks that its four files may be written there.
fn claim_out(args: &TraceArgs) -> anyhow::Result<(Claimed, [PathBuf; 4])> {
    let owner = Owner {
        command: Command::Trace,
        option: "--out",
        replaces: &[],
        tolerates: &[],
        tolerates_unrecorded: &claim::nothing,
        writes: &FILES,
    };
    let claimed = claim::claim(&args.out, &owner, args.force)?;
    let path = |i: usize| claimed.check_writable(FILES[i]);
    let paths = [path(0)?, path(1)?, path(2)?, path(3)?];
    Ok((claimed, paths))
}

/// What the trace ran, as meta.json and the titles state it: the threads and chunks the
/// strategy really uses, not those asked for.
fn trace_config(args: &TraceArgs, n: usize, cores: usize) -> TraceConfig {
    let info = args.parallel.strategy.info();
    TraceConfig {
        strategy: info.name.to_owned(),
        cores: info.effective_cores(cores),
        chunks: info.effective_chunks(args.parallel.chunks),
        n,
        steps: args.steps,
        preset: args.scene.preset,
        neighbors: args.scene.neighbors,
        seed: (args.scene.init.is_none() && args.scene.preset.is_mueller())
            .then_some(args.scene.seed),
        init: args.scene.init.as_ref().map(|p| p.display().to_string()),
    }
}

/// The traced run whose files are written, after `--compare`'s alternating untraced and
/// traced runs when asked for (each from a `fresh` simulation).
fn record(
    args: &TraceArgs,
    config: &Config,
    fresh: impl Fn() -> Simulation,
) -> anyhow::Result<(Simulation, TracedRun, Comparison)> {
    let traced = |sim: &mut Simulation| -> anyhow::Result<TracedRun> {
        Ok(run_traced(
            sim,
            args.parallel.strategy,
            config,
            args.steps,
            args.warmup,
        )?)
    };
    let mut comparison = Comparison {
        untraced: Vec::new(),
        traced: Vec::new(),
    };
    let mut last = None;
    for _ in 0..args.compare.unwrap_or(0) {
        let mut plain = fresh();
        let elapsed = run_untraced(
            &mut plain,
            args.parallel.strategy,
            config,
            args.steps,
            args.warmup,
        )?;
        comparison.untraced.push(elapsed.wall_s);
        let mut sim = fresh();
        let run = traced(&mut sim)?;
        comparison.traced.push(run.elapsed.wall_s);
        anyhow::ensure!(
            checksum_hex(&sim.state) == checksum_hex(&plain.state),
            "the traced run's final state differs from the untraced run's (a bug)"
        );
        last = Some((sim, run));
    }
    let (sim, run) = match last {
        Some(last) => last,
        None => {
            let mut sim = fresh();
            let run = traced(&mut sim)?;
            (sim, run)
        }
    };
    Ok((sim, run, comparison))
}

/// Writes the four files, each to a temporary name, and renames them into place only once
/// all four are complete (meta.json last): an error leaves the earlier files as they were.
fn write_files(
    paths: &[PathBuf; 4],
    run: &TracedRun,
    stats: &Stats,
    meta: &TraceMeta,
) -> anyhow::Result<()> {
    let [trace_json, timeline_png, stats_csv, meta_json] = paths;
    let config = &meta.config;
    let mut out = AtomicFile::create(trace_json)?;
    chrome::write(&run.trace, &stats.workers, config, &mut out)
        .context("cannot write trace.json")?;
    let mut written = vec![out];

    let mut out = AtomicFile::create(timeline_png)?;
    let [first, last] = meta.timeline_steps;
    timeline::write_png(&run.trace, &stats.workers, config, first..=last, &mut out)
        .context("cannot write timeline.png")?;
    written.push(out);

    let mut out = AtomicFile::create(stats_csv)?;
    stats::write_csv(stats, &mut out).context("cannot write stats.csv")?;
    written.push(out);

    let mut out = AtomicFile::create(meta_json)?;
    serde_json::to_writer_pretty(&mut out, meta).context("cannot write meta.json")?;
    written.push(out);

    written.into_iter().try_for_each(AtomicFile::commit)
}

fn list(paths: &[PathBuf]) -> String {
    paths
        .iter()
        .map(|p| p.display().to_string())
        .collect::<Vec<_>>()
        .join(", ")
}

/// Prints `lines`; the files are already written, so a closed standard output loses nothing.
fn print(lines: &[String], claimed: &Claimed) -> anyhow::Result<()> {
    for line in lines {
        console::line(line).with_context(|| {
            format!(
                "cannot print the summary (the files in '{}' are written)",
                claimed.dir().display()
            )
        })?;
    }
    Ok(())
}

fn ms(ns: u64) -> f64 {
    ns as f64 / 1e6
}

/// The printed summary: per worker, per pass, the `TASKS:` line, and when some workers ran
/// no kernel call, the plain statement that the timeline does not show them working.
fn summary(config: &TraceConfig, warmup: usize, stats: &Stats, wall_s: f64) -> Vec<String> {
    let mut lines = vec![
        format!(
            "trace: {}, {} steps recorded after {warmup} warm-up steps",
            config.title(),
            config.steps
        ),
        format!(
            "step loop {:.3} ms traced; serial work between passes {:.3} ms",
            wall_s * 1e3,
            ms(stats.total.serial_ns)
        ),
        format!(
            "{:<8} {:<22} {:>12} {:>10} {:>7}",
            "worker", "thread", "kernel calls", "busy ms", "idle %"
        ),
    ];
    for w in &stats.workers {
        lines.push(format!(
            "{:<8} {:<22} {:>12} {:>10.3} {:>7.1}",
            w.worker,
            w.thread_label(),
            w.kernel_calls,
            ms(w.busy_ns),
            w.idle_pct
        ));
    }
    lines.extend(pass_lines(stats));
    let t = &stats.total;
    lines.push(format!(
        "TASKS: {} kernel calls over {} steps; worker threads that ran them: {}; \
         workers idle {:.1} % of the step loop",
        t.kernel_calls, config.steps, t.worker_threads, t.idle_pct
    ));
    lines.extend(stats::idle_workers_note(
        t.workers_used,
        stats.workers.len(),
    ));
    lines
}

/// The per-pass table: calls per step, busy and span time, idle share and imbalance.
fn pass_lines(stats: &Stats) -> Vec<String> {
    let mut lines = Vec::new();
    lines.push(format!(
        "{:<12} {:>12} {:>10} {:>10} {:>7} {:>10}",
        "pass", "calls/step", "busy ms", "span ms", "idle %", "imbalance"
    ));
    for p in &stats.passes {
        let (lo, hi) = p.calls_per_step;
        let calls = if lo == hi {
            lo.to_string()
        } else {
            format!("{lo}-{hi}")
        };
        let imbalance = p
            .imbalance
            .map_or_else(|| "n/a".to_owned(), |v| format!("{v:.2}"));
        lines.push(format!(
            "{:<12} {:>12} {:>10.3} {:>10.3} {:>7.1} {:>10}",
            p.phase.as_str(),
            calls,
            ms(p.busy_ns),
            ms(p.span_ns),
            p.idle_pct,
            imbalance
        ));
    }
    lines
}

/// The smallest and the median of `v` (NaN for none).
fn min_median(v: &[f64]) -> (f64, f64) {
    let min = v.iter().copied().min_by(f64::total_cmp).unwrap_or(f64::NAN);
    (min, crate::results::stats::median(v))
}

/// The measured comparison, and the estimate from the calibrated cost per kernel call
/// (`cost_ns`), spread over the workers, relative to the untraced minimum.
fn comparison_lines(c: &Comparison, stats: &Stats, cost_ns: f64) -> Vec<String> {
    let (umin, umed) = min_median(&c.untraced);
    let (tmin, tmed) = min_median(&c.traced);
    let calls = stats.total.kernel_calls as f64;
    let added_s = calls * cost_ns * 1e-9 / stats.workers.len().max(1) as f64;
    vec![
        format!(
            "compare ({} runs each, alternating): untraced min {:.4} s median {:.4} s; \
             traced min {:.4} s median {:.4} s; overhead {:+.1} % (min), {:+.1} % (median)",
            c.untraced.len(),
            umin,
            umed,
            tmin,
            tmed,
            100.0 * (tmin / umin - 1.0),
            100.0 * (tmed / umed - 1.0)
        ),
        format!(
            "recording costs {cost_ns:.0} ns per kernel call on this machine: {} calls over {} \
             workers add about {:.2} ms, {:.1} % of the untraced minimum",
            stats.total.kernel_calls,
            stats.workers.len(),
            added_s * 1e3,
            100.0 * added_s / umin
        ),
    ]
}
