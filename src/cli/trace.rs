//! `bench-sph trace`: a few steps with every kernel call recorded; writes trace.json,
//! timeline.png, stats.csv and meta.json and prints a summary.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use anyhow::Context;
use clap::Args;
use serde::Serialize;
use sph_strategies::{Config, StrategyName};

use crate::checksum::checksum_hex;
use crate::run::run_timed;
use crate::solver::Simulation;
use crate::trace::stats::{self, Stats};
use crate::trace::{TraceConfig, TracedRun, chrome, run_traced, timeline};

/// Options of `trace`.
#[derive(Debug, Clone, Args)]
pub struct TraceArgs {
    /// The scene: preset, N, neighbour search, seed, initial state.
    #[command(flatten)]
    pub scene: super::scene::SceneArgs,
    /// Parallel strategy to trace (see `bench-sph list`).
    #[arg(long, value_parser = super::strategy)]
    pub strategy: StrategyName,
    /// Worker threads [default: the machine's hardware threads].
    #[arg(long, value_parser = super::cores)]
    pub cores: Option<usize>,
    /// Chunks per pass, for strategies that use chunks.
    #[arg(long, default_value_t = 10, value_parser = super::chunks)]
    pub chunks: usize,
    /// Number of steps to trace.
    #[arg(long, default_value_t = 3, value_parser = super::steps)]
    pub steps: usize,
    /// Output directory (created if missing): trace.json, timeline.png, stats.csv, meta.json.
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// Draw only the last K steps in timeline.png [default: all steps, at most the last 3].
    #[arg(long, value_name = "K", value_parser = super::positive)]
    pub timeline_steps: Option<usize>,
    /// Also time REPS untraced and REPS traced runs of the same steps, alternately, and print
    /// the minimum and median wall time of each: the cost of tracing. The files then come
    /// from the last traced run.
    #[arg(long, value_name = "REPS", value_parser = super::positive)]
    pub compare: Option<usize>,
}

/// The files `trace` writes, opened before anything runs so that a bad --out costs nothing.
struct Outputs {
    dir: PathBuf,
    trace_json: BufWriter<File>,
    timeline_png: BufWriter<File>,
    stats_csv: BufWriter<File>,
    meta_json: BufWriter<File>,
}

impl Outputs {
    fn create(dir: &Path) -> anyhow::Result<Self> {
        std::fs::create_dir_all(dir)
            .with_context(|| format!("cannot create output directory '{}'", dir.display()))?;
        let open = |name: &str| -> anyhow::Result<BufWriter<File>> {
            let path = dir.join(name);
            let file = File::create(&path)
                .with_context(|| format!("cannot write '{}'", path.display()))?;
            Ok(BufWriter::new(file))
        };
        Ok(Outputs {
            dir: dir.to_owned(),
            trace_json: open("trace.json")?,
            timeline_png: open("timeline.png")?,
            stats_csv: open("stats.csv")?,
            meta_json: open("meta.json")?,
        })
    }

    fn path(&self, name: &str) -> String {
        self.dir.join(name).display().to_string()
    }

    /// Removes the files (best effort: the error being reported matters more).
    fn discard(&self) {
        for name in NAMES {
            let _ = std::fs::remove_file(self.dir.join(name));
        }
    }
}

/// The files `trace` writes into its directory.
const NAMES: [&str; 4] = ["trace.json", "timeline.png", "stats.csv", "meta.json"];

/// What `meta.json` holds: the configuration, the run's timing and its totals.
#[derive(Debug, Serialize)]
struct Meta<'a> {
    #[serde(flatten)]
    config: &'a TraceConfig,
    wall_s: f64,
    cpu_s: f64,
    kernel_calls: usize,
    worker_threads: usize,
    checksum: String,
    timeline_steps: [usize; 2],
}

/// Minimum and median of untraced and traced wall times.
struct Comparison {
    untraced: Vec<f64>,
    traced: Vec<f64>,
}

/// Runs `trace`. On failure (a diverging run, say) the files it had opened are removed, so
/// that a failed trace never leaves a directory that looks like a trace.
pub fn run(args: &TraceArgs) -> anyhow::Result<()> {
    let mut out = Outputs::create(&args.out)?;
    let result = trace_and_write(args, &mut out);
    if result.is_err() {
        out.discard();
    }
    result
}

fn trace_and_write(args: &TraceArgs, out: &mut Outputs) -> anyhow::Result<()> {
    let (state, domain) = args.scene.initial_state()?;
    let cores = args.cores.unwrap_or_else(super::hardware_threads);
    let strategy_config = Config {
        cores,
        chunks: args.chunks,
    };
    let info = args.strategy.info();
    let config = TraceConfig {
        strategy: info.name.to_owned(),
        cores: crate::trace::expected_workers(args.strategy, cores),
        chunks: info.uses_chunks.then_some(args.chunks),
        n: state.len(),
        steps: args.steps,
        preset: args.scene.preset,
        neighbors: args.scene.neighbors,
        seed: args.scene.init.is_none().then_some(args.scene.seed),
        init: args.scene.init.as_ref().map(|p| p.display().to_string()),
    };
    let fresh = || {
        Simulation::new(
            args.scene.preset.params(),
            domain,
            state.clone(),
            args.scene.neighbors,
        )
    };
    let traced = |sim: &mut Simulation| -> anyhow::Result<TracedRun> {
        Ok(run_traced(
            sim,
            args.strategy,
            &strategy_config,
            args.steps,
        )?)
    };

    let mut comparison = Comparison {
        untraced: Vec::new(),
        traced: Vec::new(),
    };
    let mut last = None;
    for _ in 0..args.compare.unwrap_or(0) {
        let mut plain = fresh();
        let elapsed = run_timed(&mut plain, args.strategy, &strategy_config, args.steps)?;
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

    let stats = stats::compute(&run.trace);
    let shown = args.timeline_steps.unwrap_or(3).min(args.steps);
    let window = [args.steps + 1 - shown, args.steps];
    chrome::write(&run.trace, &stats.workers, &config, &mut out.trace_json)
        .context("cannot write trace.json")?;
    timeline::write_png(
        &run.trace,
        &stats.workers,
        &config,
        window[0]..=window[1],
        &mut out.timeline_png,
    )
    .context("cannot write timeline.png")?;
    stats::write_csv(&stats, &mut out.stats_csv).context("cannot write stats.csv")?;
    let meta = Meta {
        config: &config,
        wall_s: run.elapsed.wall_s,
        cpu_s: run.elapsed.cpu_s,
        kernel_calls: stats.total.kernel_calls,
        worker_threads: stats.total.worker_threads,
        checksum: checksum_hex(&sim.state),
        timeline_steps: window,
    };
    serde_json::to_writer_pretty(&mut out.meta_json, &meta).context("cannot write meta.json")?;
    for (name, file) in [
        ("trace.json", &mut out.trace_json),
        ("timeline.png", &mut out.timeline_png),
        ("stats.csv", &mut out.stats_csv),
        ("meta.json", &mut out.meta_json),
    ] {
        file.flush()
            .with_context(|| format!("cannot write '{}'", out.dir.join(name).display()))?;
    }

    let mut stdout = std::io::stdout().lock();
    print_summary(&mut stdout, &config, &stats, run.elapsed.wall_s)?;
    if args.compare.is_some() {
        let cost_ns = crate::trace::executor::recording_cost_ns(200_000);
        print_comparison(&mut stdout, &comparison, &stats, cost_ns)?;
    }
    let written: Vec<String> = NAMES.iter().map(|n| out.path(n)).collect();
    writeln!(stdout, "wrote {}", written.join(", "))?;
    Ok(())
}

fn ms(ns: u64) -> f64 {
    ns as f64 / 1e6
}

/// The printed summary: per worker, per pass, and the `TASKS:` line.
fn print_summary(
    out: &mut impl Write,
    config: &TraceConfig,
    stats: &Stats,
    wall_s: f64,
) -> std::io::Result<()> {
    writeln!(out, "trace: {}, {} steps", config.title(), config.steps)?;
    writeln!(
        out,
        "step loop {:.3} ms traced; serial work between passes {:.3} ms",
        wall_s * 1e3,
        ms(stats.total.serial_ns)
    )?;
    writeln!(
        out,
        "{:<8} {:<22} {:>12} {:>10} {:>7}",
        "worker", "thread", "kernel calls", "busy ms", "idle %"
    )?;
    for w in &stats.workers {
        writeln!(
            out,
            "{:<8} {:<22} {:>12} {:>10.3} {:>7.1}",
            w.worker,
            w.thread_label(),
            w.kernel_calls,
            ms(w.busy_ns),
            w.idle_pct
        )?;
    }
    writeln!(
        out,
        "{:<12} {:>12} {:>10} {:>10} {:>7} {:>10}",
        "pass", "calls/step", "busy ms", "span ms", "idle %", "imbalance"
    )?;
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
        writeln!(
            out,
            "{:<12} {:>12} {:>10.3} {:>10.3} {:>7.1} {:>10}",
            p.phase.as_str(),
            calls,
            ms(p.busy_ns),
            ms(p.span_ns),
            p.idle_pct,
            imbalance
        )?;
    }
    let t = &stats.total;
    writeln!(
        out,
        "TASKS: {} kernel calls over {} steps; worker threads that ran them: {}; \
         workers idle {:.1} % of the step loop",
        t.kernel_calls, config.steps, t.worker_threads, t.idle_pct
    )
}

fn min_median(v: &[f64]) -> (f64, f64) {
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    let mid = s.len() / 2;
    let median = if s.len() % 2 == 1 {
        s[mid]
    } else {
        (s[mid - 1] + s[mid]) / 2.0
    };
    (s[0], median)
}

/// The measured comparison, and the estimate from the calibrated cost per kernel call
/// (`cost_ns`), spread over the workers, relative to the untraced minimum.
fn print_comparison(
    out: &mut impl Write,
    c: &Comparison,
    stats: &Stats,
    cost_ns: f64,
) -> std::io::Result<()> {
    let (umin, umed) = min_median(&c.untraced);
    let (tmin, tmed) = min_median(&c.traced);
    writeln!(
        out,
        "compare ({} runs each, alternating): untraced min {:.4} s median {:.4} s; \
         traced min {:.4} s median {:.4} s; overhead {:+.1} % (min), {:+.1} % (median)",
        c.untraced.len(),
        umin,
        umed,
        tmin,
        tmed,
        100.0 * (tmin / umin - 1.0),
        100.0 * (tmed / umed - 1.0)
    )?;
    let calls = stats.total.kernel_calls as f64;
    let added_s = calls * cost_ns * 1e-9 / stats.workers.len().max(1) as f64;
    writeln!(
        out,
        "recording costs {cost_ns:.0} ns per kernel call on this machine: {} calls over {} \
         workers add about {:.2} ms, {:.1} % of the untraced minimum",
        stats.total.kernel_calls,
        stats.workers.len(),
        added_s * 1e3,
        100.0 * added_s / umin
    )
}
