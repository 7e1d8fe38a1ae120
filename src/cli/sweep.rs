//! `bench-sph sweep`: the cores × chunks study over every strategy.

use std::path::{Path, PathBuf};

use anyhow::Context;
use clap::{Arg, Args};
use sph_strategies::StrategyName;

use crate::models::Preset;
use crate::results::shard::Shard;
use crate::sph::neighbors::NeighborMode;
use crate::sweep::params::SweepParams;
use crate::sweep::range::{self, Axis};
use crate::sweep::schedule::Schedule;
use crate::sweep::{Request, Target};
use crate::topology::Pin;

/// `--quick`: chunks, steps and trials of the README's quickstart.
const QUICK_CHUNKS: &str = "10,45,90";
/// See [`QUICK_CHUNKS`].
const QUICK_STEPS: usize = 300;
/// See [`QUICK_CHUNKS`].
const QUICK_TRIALS: usize = 3;

/// The options that describe a new sweep: `--resume` takes its parameters from DIR/meta.json
/// and cannot be used with any of them.
///
/// Not an `ArgGroup` that conflicts with `--resume`: clap's error for `--resume DIR --n 5`
/// would then list every member of the group instead of naming `--n`.
const NEW_SWEEP_ONLY: [&str; 21] = [
    "cores",
    "chunks",
    "strategies",
    "preset",
    "neighbors",
    "n",
    "steps",
    "trials",
    "warmup",
    "schedule",
    "confirm_rounds",
    "seed",
    "out",
    "force",
    "quick",
    "fake_timings",
    "fake_contention",
    "shard",
    "pin",
    "pass_cost",
    "anchor",
];

/// Makes each of [`NEW_SWEEP_ONLY`] conflict with `--resume` (in place, keeping clap's order).
fn not_with_resume(arg: Arg) -> Arg {
    match NEW_SWEEP_ONLY.contains(&arg.get_id().as_str()) {
        true => arg.conflicts_with("resume"),
        false => arg,
    }
}

/// Options of `sweep`.
#[derive(Debug, Clone, Args)]
#[command(mut_args(not_with_resume))]
pub struct SweepArgs {
    /// Worker threads: N, A..B, A..B:S or a comma list [default: 1..the hardware threads].
    #[arg(long, value_name = "RANGE")]
    pub cores: Option<String>,
    /// Chunks per pass, for strategies that use chunks: N, A..B (step 10), A..B:S, a comma
    /// list, or `paper` (2,4,8,12,16,20,25,35,45,60,75,100,150,200,250,333,400).
    #[arg(long, value_name = "RANGE", default_value = "paper")]
    pub chunks: String,
    /// Strategies, comma-separated (see `bench-sph list`) [default: all]. seq at 1 core is
    /// measured in any case: it is the reference of speedup and checksum.
    #[arg(long, value_name = "LIST", value_delimiter = ',', value_parser = super::values::strategy())]
    pub strategies: Vec<StrategyName>,
    /// Presets, comma-separated.
    #[arg(long, value_delimiter = ',', default_value = "seed", value_parser = super::values::preset())]
    pub preset: Vec<Preset>,
    /// Neighbour searches, comma-separated.
    #[arg(long, value_delimiter = ',', default_value = "all-pairs", value_parser = super::values::neighbors())]
    pub neighbors: Vec<NeighborMode>,
    /// Particle counts: N, a comma list, or A..B:S.
    #[arg(long, value_name = "LIST", default_value = "1000")]
    pub n: String,
    /// Steps per run.
    #[arg(long, default_value_t = 1000, value_parser = super::steps)]
    pub steps: usize,
    /// Rounds (1 ..= 1000): in each, every cell of a group runs once, in a shuffled order.
    /// Intervals need 3 or more.
    #[arg(long, default_value_t = 5, value_parser = super::trials)]
    pub trials: usize,
    /// Untimed seq runs before each group's first round, at least one (0 ..= 1000); with
    /// --schedule cells, untimed runs before each cell's trials.
    #[arg(long, default_value_t = 1, value_parser = super::warmup)]
    pub warmup: usize,
    /// The order of the runs: rounds (shuffled, so the machine's drift hits every cell alike)
    /// or cells (each cell's trials back to back, as the first versions did; for comparison).
    #[arg(long, default_value = "rounds", value_parser = super::values::schedule())]
    pub schedule: Schedule,
    /// Rounds (0 ..= 1000) that measure each strategy's best cell per core count (and the
    /// runner-up, for strategies with chunks) again after the grid: the findings rest on them
    /// [default: --trials; 0 with --shard, which has none].
    #[arg(long, value_name = "N", value_parser = super::confirm_rounds)]
    pub confirm_rounds: Option<usize>,
    /// Before each round, wait up to SECONDS (0 ..= 3600) for other work to leave the machine
    /// quiet, saying so; then measure anyway. Also with --resume.
    #[arg(long, value_name = "SECONDS", default_value_t = 0, value_parser = super::wait_quiet)]
    pub wait_quiet: u64,
    /// With --resume: measure again, from their first round, the groups that have a
    /// contended cell.
    #[arg(long, requires = "resume")]
    pub remeasure_contended: bool,
    /// Seed of the initial jitter.
    #[arg(long, default_value_t = 2019)]
    pub seed: u64,
    /// Results directory [default: results/<UTC timestamp>]. Must not exist or be empty,
    /// unless --force.
    #[allow(rustdoc::invalid_html_tags)] // `--help` shows this text as it is: no markup
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Continue the sweep in DIR with the parameters of DIR/meta.json: finished cells are
    /// kept, unfinished ones run (again).
    #[arg(long, value_name = "DIR")]
    pub resume: Option<PathBuf>,
    /// Replace the results of an earlier sweep or merge in --out (the files its record,
    /// bench-sph-files.json, gives to them, and the report drawn there); other files stay
    /// untouched.
    #[arg(long)]
    pub force: bool,
    /// Thread placements to measure, comma-separated: none (the operating system decides),
    /// compact (SMT siblings of one core first), spread (one thread per physical core
    /// first). Each is a cell of every strategy but seq, which runs unpinned.
    #[arg(long, value_name = "LIST", value_delimiter = ',', default_value = "none", value_parser = super::values::pin())]
    pub pin: Vec<Pin>,
    /// Run only shard I of K of the plan (1 ≤ I ≤ K ≤ 1024), e.g. one node of a batch job:
    /// the plan's cells other than seq, dealt round-robin, plus the seq cell of every group
    /// it touches. Merge the K directories with `bench-sph merge`; the report comes after.
    #[arg(long, value_name = "I/K", value_parser = clap::value_parser!(Shard))]
    pub shard: Option<Shard>,
    /// After the cells, measure what a pass costs each strategy at each core count (as
    /// `bench-sph overhead` does, 5 µs of work a thread) into pass-cost.csv; the report sets it
    /// beside the workload's own pass. Adds about a tenth of a second per strategy and core
    /// count (std-static: a second).
    #[arg(long)]
    pub pass_cost: bool,
    /// After the cells, run PATH, the plain C++ loop's OpenMP build
    /// (`scripts/build-plain-loop.sh`), at each core count in rounds as the cells ran, for
    /// each group of the seed preset with all-pairs, into anchor.csv; the report sets its
    /// speedups beside the strategies'.
    #[arg(long, value_name = "PATH")]
    pub anchor: Option<PathBuf>,
    /// Do not draw charts at the end.
    #[arg(long)]
    pub no_plots: bool,
    /// A small study, about 10 s of runs on 2 cores: the defaults, but 300 steps, chunks
    /// 10,45,90 and 3 trials per cell.
    #[arg(long, conflicts_with_all = ["steps", "chunks", "trials"])]
    pub quick: bool,
    /// Test hooks (only with the `testing` cargo feature).
    #[cfg(feature = "testing")]
    #[command(flatten)]
    pub hooks: super::testing::SweepHooks,
}

impl SweepArgs {
    /// The test hooks given; none in a build without the `testing` feature.
    fn hooks(&self) -> super::testing::SweepHooks {
        #[cfg(feature = "testing")]
        return self.hooks.clone();
        #[cfg(not(feature = "testing"))]
        super::testing::SweepHooks::default()
    }

    /// The parameters of a new sweep, with every list expanded and checked.
    pub fn params(&self) -> anyhow::Result<SweepParams> {
        let list = |option: &str, spec: &str, axis: Axis| {
            range::parse(spec, axis).with_context(|| format!("--{option} '{spec}'"))
        };
        let default_cores = format!("1..{}", super::hardware_threads());
        let (chunks, steps, trials) = if self.quick {
            (QUICK_CHUNKS, QUICK_STEPS, QUICK_TRIALS)
        } else {
            (self.chunks.as_str(), self.steps, self.trials)
        };
        let mut strategies = if self.strategies.is_empty() {
            StrategyName::ALL.to_vec()
        } else {
            self.strategies.clone()
        };
        strategies.sort();
        strategies.dedup();
        let (mut presets, mut neighbors) = (self.preset.clone(), self.neighbors.clone());
        presets.sort();
        presets.dedup();
        neighbors.sort();
        neighbors.dedup();
        Ok(SweepParams {
            strategies,
            presets,
            neighbors,
            n: list("n", &self.n, Axis::Particles)?,
            steps,
            cores: list(
                "cores",
                self.cores.as_deref().unwrap_or(&default_cores),
                Axis::Cores,
            )?,
            chunks: list("chunks", chunks, Axis::Chunks)?,
            trials,
            warmup: self.warmup,
            schedule: self.schedule,
            confirm_rounds: match (self.confirm_rounds, self.shard) {
                (Some(k), Some(shard)) if k > 0 => anyhow::bail!(
                    "--confirm-rounds {k} with --shard {shard}: a shard holds only part of each \
                     strategy's cells, so it cannot choose the best ones; confirm after the \
                     merge with a sweep of the chosen cells, or leave --confirm-rounds out"
                ),
                (Some(k), _) => k,
                (None, Some(_)) => 0,
                (None, None) => trials,
            },
            seed: self.seed,
            simd: Some(crate::simd::current()),
            fake_timings: self.hooks().fake_timings,
            fake_contention: self.hooks().fake_contention,
            pin: {
                let mut pins = self.pin.clone();
                pins.sort();
                pins.dedup();
                pins
            },
            shard: self.shard,
            pass_cost: self.pass_cost,
            anchor: self.anchor.as_deref().map(anchor_path).transpose()?,
        })
    }

    /// What to run.
    pub fn request(&self) -> anyhow::Result<Request> {
        let target = match &self.resume {
            Some(dir) => Target::Resume { dir: dir.clone() },
            None => Target::New {
                params: Box::new(self.params()?),
                out: self.out.clone(),
                force: self.force,
            },
        };
        Ok(Request {
            target,
            remeasure_contended: self.remeasure_contended,
            wait_quiet_s: self.wait_quiet,
            stop_after_runs: self.hooks().stop_after_runs,
            command_line: std::env::args_os()
                .map(|a| a.to_string_lossy().into_owned())
                .collect(),
        })
    }
}

/// Runs `sweep`, then (when it is complete) `report` on its directory, and prints what it
/// found, the charts and where everything is: cli → sweep → report, as hyperfine's
/// cli → run → export.
pub fn run(args: &SweepArgs) -> anyhow::Result<()> {
    let finished = crate::sweep::run(args.request()?)?;
    let charts = if let Some(shard) = finished.shard()
        && shard.count == 1
    {
        Ok(format!(
            "Charts: not drawn for a shard: shard {shard} holds the whole plan; `bench-sph \
             merge {} --out DIR` and `bench-sph report DIR` draw them.",
            finished.dir().display()
        ))
    } else if let Some(shard) = finished.shard() {
        Ok(format!(
            "Charts: not drawn for shard {shard} alone: once every shard is done, \
             `bench-sph merge SHARD_DIR... --out DIR` and `bench-sph report DIR`."
        ))
    } else if finished.is_complete() {
        charts(finished.dir(), args.no_plots)
    } else {
        Ok(String::new())
    };
    // Standard output may be gone (`| head`, a full disk): the sweep's files are complete by
    // now, so the sweep ends with its own status first, then with the failed print (exit 1,
    // as in every command).
    let mut text = finished.best_text();
    if let Ok(charts) = &charts {
        text.push_str(charts);
        text.push('\n');
    }
    text.push_str(&finished.paths_text());
    let printed = crate::output::console::line(text.trim_end()).with_context(|| {
        format!(
            "cannot write to standard output (the sweep's files in '{}' are written)",
            finished.dir().display()
        )
    });
    charts?;
    finished.outcome()?;
    printed
}

/// The one place where a finished sweep's charts are made: `bench-sph report` on the sweep's
/// directory, writing into it. A drawing failure is an error, but the CSVs and meta.json are
/// already complete by then.
fn charts(dir: &Path, no_plots: bool) -> anyhow::Result<String> {
    if no_plots {
        return Ok("Charts: skipped (--no-plots).".to_owned());
    }
    // The sweep has claimed its directory already (foreign files stay only where its own
    // --force allowed them) and still holds its lock, which the report shares: the report
    // writes beside those files, never over them, and records its own as the report's.
    let written =
        crate::report::generate(&[dir.to_path_buf()], dir, &[], true).with_context(|| {
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

/// `--anchor`'s program as an absolute path (so that `--resume` from another directory runs
/// it), refused here when there is no such file.
fn anchor_path(path: &Path) -> anyhow::Result<PathBuf> {
    let found = path
        .canonicalize()
        .with_context(|| format!("--anchor '{}': no such program", path.display()))?;
    if !found.is_file() {
        anyhow::bail!("--anchor '{}': not a program file", path.display());
    }
    // meta.json records the path as text.
    if found.to_str().is_none() {
        anyhow::bail!(
            "--anchor '{}': the path is not valid UTF-8; give a path without such characters",
            path.display()
        );
    }
    Ok(found)
}
