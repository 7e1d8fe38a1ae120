//! The `bench-sph` command line (clap derive): one module per command, plus the options
//! several commands share (`scene`: the initial state; `parallel`: strategy, cores, chunks)
//! and the CLI's names for the domain's enums (`values`).

mod list;
mod merge;
mod overhead;
mod parallel;
mod render;
mod report;
mod scene;
mod simulate;
mod speedup;
mod sweep;
mod testing;
mod trace;
mod validate;
mod values;
#[cfg(feature = "viewer")]
mod view;

use clap::{Parser, Subcommand};

use crate::limits;

pub use merge::MergeArgs;
pub use overhead::OverheadArgs;
pub use render::RenderArgs;
pub use report::ReportArgs;
pub use simulate::SimulateArgs;
pub use speedup::SpeedupArgs;
pub use sweep::SweepArgs;
pub use trace::TraceArgs;
pub use validate::ValidateArgs;

/// bench-sph: which parallel strategy wins for a 2D SPH fluid, by how much and why.
#[derive(Debug, Parser)]
#[command(name = "bench-sph", version, about, long_about = None)]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
    /// Instructions for the all-pairs neighbour tests, Müller's force pass and (avx512) the
    /// grid's candidate scan: portable, avx2 or avx512 [default: the widest this CPU runs].
    /// Every path gives the same bits; a path the CPU lacks is an error.
    #[arg(long, global = true, value_parser = values::simd())]
    pub simd: Option<crate::simd::SimdPath>,
}

/// The commands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Run the dam break once and report its time.
    #[command(after_help = "Examples:\n  \
        bench-sph simulate                               # the paper's run: seed preset, N = 1000, 1000 steps\n  \
        bench-sph simulate --neighbors grid --n 100000 --steps 10\n  \
        bench-sph simulate --steps 100 --dump final.csv --json\n  \
        bench-sph simulate --preset wcsph --resolution 40 --neighbors grid --t-end 0.5  # SI units, 0.5 s")]
    Simulate(SimulateArgs),
    /// A strategy against seq, a step of each in turn in one process: speedup and efficiency
    /// with the spread of their step-by-step ratio.
    #[command(
        after_help = "The two copies run the same steps from the same state, taking turns step by step \
        (which goes first alternating), so that a machine whose speed drifts slows both alike; both \
        must end with the same checksum. Each step is timed as simulate times its steps; the \
        strategy's threads are woken first and, since they fall asleep while seq steps, roused \
        (untimed) before each of its steps, as they would be awake in a run of their own.\n\n\
        Examples:\n  \
        bench-sph speedup --strategy crossbeam-pool --cores 2 --neighbors grid --n 1000000 --steps 10\n  \
        bench-sph speedup --strategy rayon-chunks --cores 2 --chunks 45 --steps 1000 --json"
    )]
    Speedup(SpeedupArgs),
    /// What a pass costs each strategy apart from its work, at each core count, with its
    /// interval.
    #[command(
        after_help = "Each pass has --work-us of work a thread (a clock loop), cut into one chunk a \
        thread; a pass ends in that time only if every thread takes its share at once, and what it \
        takes beyond is the strategy's own cost of forking, handing out and joining the pass. A \
        pass of the paper's workload (all-pairs, N = 1000) is about 30-100 µs of work on one core: \
        set the two side by side to see where a strategy's speedup bends. Each cell starts its \
        threads and wakes them before each round, as a run does; the cells take turns round by \
        round.\n\n\
        Examples:\n  \
        bench-sph overhead                                # every strategy, 1..the hardware threads\n  \
        bench-sph overhead --strategies team,rayon-chunks --cores 2 --work-us 0 --json"
    )]
    Overhead(OverheadArgs),
    /// List the parallel strategies, one per line: name, then what it does.
    List,
    /// Animate the dam break: an animated GIF (or PNG frames), one frame every K steps.
    #[command(
        after_help = "Frame 0 is the initial state; --steps S --every K gives floor(S/K) + 1 frames.\n\n\
        Examples:\n  \
        bench-sph render                                 # seed preset, N = 1000, 1000 steps -> dambreak.gif\n  \
        bench-sph render --every 15 --color density --out density.gif\n  \
        bench-sph render --n 100 --steps 200 --frames frames/  # PNG frames instead\n  \
        bench-sph render --preset wcsph --resolution 40 --neighbors grid --t-end 1 --every 40 --out wcsph.gif"
    )]
    Render(RenderArgs),
    /// Measure every strategy over a cores × chunks grid: trials.csv, summary.csv, meta.json.
    #[command(
        after_help = "--trials K rounds: in each, every cell (strategy, cores, chunks) of a group and its seq run the \
        whole simulation once from the same initial state, in a shuffled order; every run's final checksum must \
        equal seq's. Runs are written as they finish; Ctrl-C, SIGTERM or SIGHUP keep them, and --resume DIR continues.\n\n\
        Examples:\n  \
        bench-sph sweep --cores 1..6 --chunks 10..200          # the paper's study, every strategy\n  \
        bench-sph sweep --cores 1,2 --chunks 10,50 --n 300 --steps 50 --trials 3 --no-plots\n  \
        bench-sph sweep --strategies rayon-chunks,crossbeam-pool --neighbors all-pairs,grid --out results/grid\n  \
        bench-sph sweep --resume results/2026-11-22T031500Z\n  \
        bench-sph sweep --cores 1..16 --shard 2/4 --out results/study/shard-2   # one node's part; then bench-sph merge"
    )]
    Sweep(SweepArgs),
    /// Merge the shard directories of `sweep --shard I/K` into one results directory.
    #[command(
        after_help = "Refuses shards of different plans, splits, builds or machines (that is a comparison: \
        `bench-sph report A B`), a shard given twice, and missing cells or a shard whose seq is unusable \
        unless --allow-partial. Checks every row as `bench-sph report` does, and against the shard's plan, \
        naming each row it leaves out and why. Each cell \
        keeps the speedup its own shard measured against its own seq (column reference_shard); every \
        shard's seq rows go to references.csv, and the merge warns when they disagree beyond their \
        95 % intervals.\n\n\
        Examples:\n  \
        bench-sph sweep --cores 1..16 --chunks 10..200 --shard 1/3 --out results/study/shard-1   # on node 1, and so on\n  \
        bench-sph merge results/study/shard-1 results/study/shard-2 results/study/shard-3 --out results/study/merged\n  \
        bench-sph report results/study/merged"
    )]
    Merge(MergeArgs),
    /// Turn results directories into PNG charts and REPORT.md (also run at the end of a sweep).
    #[command(
        after_help = "Charts: runtime and CPU time against chunks per core count, best runtime and speedup \
        against cores (with the paper's speedups where comparable), every strategy's speedup with error bars, \
        efficiency and Karp–Flatt serial fraction, all-pairs against grid. Trace directories (timeline.png + \
        stats.csv) under the results or output directory are embedded; --trace adds others. Directories \
        of different machines (meta.json) are compared instead, one side per machine: speedup and \
        efficiency per strategy with a line per machine, and each machine's best strategy; --compare \
        does the same with one side per directory.\n\n\
        Examples:\n  \
        bench-sph report results/2026-11-22T031500Z                 # writes the charts and REPORT.md there\n  \
        bench-sph report results/paper results/grid --out report    # several sweeps as one study\n  \
        bench-sph report laptop/ server/ --out compare              # two machines: compared, not pooled\n  \
        bench-sph report results/paper --out report --trace trace-chunks"
    )]
    Report(ReportArgs),
    /// Record where each worker spends its time over a few steps: trace.json (Perfetto),
    /// timeline.png, stats.csv, meta.json and a summary.
    #[command(
        after_help = "One event per kernel call (per chunk, per task for rayon-spawn, per leaf for rayon-iter), \
        never per particle; trace.json opens in https://ui.perfetto.dev or chrome://tracing.\n\n\
        Examples:\n  \
        bench-sph trace --strategy rayon-chunks --cores 2 --chunks 45 --out trace-chunks\n  \
        bench-sph trace --strategy rayon-spawn --cores 2 --steps 2 --out trace-spawn\n  \
        bench-sph trace --strategy rayon-chunks --cores 2 --chunks 45 --steps 300 --compare 5 --out /tmp/t  # tracing's cost"
    )]
    Trace(TraceArgs),
    /// Check the wcsph dam break against Martin & Moyce (1952): surge front and column height,
    /// three verdicts; writes surge_front.csv, column_height.csv and validation.png.
    #[command(
        after_help = "Runs the square column (n² = 2) to T = t·√(2g/a) = 3.4 with the grid search, \
        samples every 0.01 s, and checks: H(τ) within 6 % for τ <= 2; the front's slope dZ/dT over \
        T in [1.5, 2.8] within 5 %; Z within 10 % for T in [0.8, 3.0] with the simulated front shifted \
        right by 0.175 (the experiment's gate delays its early front). Exits non-zero if a verdict \
        fails (the files are still written).\n\n\
        Examples:\n  \
        bench-sph validate                               # R = 40, into validation/\n  \
        bench-sph validate --resolution 20 --out /tmp/v --json\n  \
        bench-sph validate --strategy crossbeam-pool --cores 2"
    )]
    Validate(ValidateArgs),
    /// Watch the dam break live in a window (cargo feature `viewer`).
    #[cfg(feature = "viewer")]
    #[command(
        after_help = "Keys: space pauses, r resets, + and - double and halve N, s moves to the next \
        strategy, c switches the colour between speed and density, q or Esc quits.\n\n\
        Examples:\n  \
        bench-sph view\n  \
        bench-sph view --n 4000 --strategy rayon-chunks --cores 4"
    )]
    View(view::ViewArgs),
}

/// Parses the command line and runs the command.
pub fn run() -> anyhow::Result<()> {
    let Cli { command, simd } = Cli::parse();
    if let Some(path) = simd {
        crate::simd::choose(path)?;
    }
    // The sweep keeps its finished runs when asked to stop; every other command just stops,
    // and must not leave half-written temporary files behind.
    crate::signals::install(match command {
        Command::Sweep(_) => crate::signals::Stop::BetweenRuns,
        _ => crate::signals::Stop::Now,
    });
    match command {
        Command::Simulate(args) => simulate::run(&args),
        Command::Speedup(args) => speedup::run(&args),
        Command::Overhead(args) => overhead::run(&args),
        Command::List => list::run(&mut std::io::stdout().lock()),
        Command::Render(args) => render::run(&args),
        Command::Sweep(args) => sweep::run(&args),
        Command::Merge(args) => merge::run(&args),
        Command::Report(args) => report::run(&args),
        Command::Trace(args) => trace::run(&args),
        Command::Validate(args) => validate::run(&args),
        #[cfg(feature = "viewer")]
        Command::View(args) => view::run(&args),
    }
}

/// A whole number from `min` to `max`; errors name the quantity `what` and the range, so
/// that `0` and `-3` are answered with what is allowed.
fn in_range(s: &str, what: &'static str, min: usize, max: usize) -> Result<usize, String> {
    let v = s.parse::<usize>().map_err(|_| {
        format!("'{s}' is not a whole number; {what} must be between {min} and {max}")
    })?;
    limits::check(what, v, min, max).map_err(|e| e.to_string())
}

/// A whole number from 1 to `max`; the error names the quantity `what`.
fn count(s: &str, what: &'static str, max: usize) -> Result<usize, String> {
    in_range(s, what, 1, max)
}

/// Repetitions of a timed comparison: 1 ..= [`limits::MAX_TRIALS`].
fn repetitions(s: &str) -> Result<usize, String> {
    count(s, "repetitions", limits::MAX_TRIALS)
}

/// A worker-thread count: 1 ..= [`limits::MAX_CORES`].
fn cores(s: &str) -> Result<usize, String> {
    count(s, "cores", limits::MAX_CORES)
}

/// A chunk count: 1 ..= [`limits::MAX_CHUNKS`].
fn chunks(s: &str) -> Result<usize, String> {
    count(s, "chunks", limits::MAX_CHUNKS)
}

/// A step count: 1 ..= [`limits::MAX_STEPS`].
fn steps(s: &str) -> Result<usize, String> {
    count(s, "steps", limits::MAX_STEPS)
}

/// A particle count: 1 ..= [`limits::MAX_PARTICLES`].
fn particles(s: &str) -> Result<usize, String> {
    count(s, "particles", limits::MAX_PARTICLES)
}

/// A `wcsph` resolution R = a/dx: within [`RESOLUTIONS`](crate::models::wcsph::params::RESOLUTIONS).
fn resolution(s: &str) -> Result<usize, String> {
    let range = crate::models::wcsph::params::RESOLUTIONS;
    in_range(s, "resolution", *range.start(), *range.end())
}

/// A simulated time in seconds: 0 < t ≤ [`limits::MAX_T_END_S`].
fn t_end(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(t) if t > 0.0 && t <= limits::MAX_T_END_S => Ok(t),
        _ => Err(format!(
            "'{s}' is not a time in seconds above 0 and at most {}",
            limits::MAX_T_END_S
        )),
    }
}

/// Timed trials per cell: 1 ..= [`limits::MAX_TRIALS`].
fn trials(s: &str) -> Result<usize, String> {
    count(s, "trials", limits::MAX_TRIALS)
}

/// Confirmation rounds: 0 ..= [`limits::MAX_TRIALS`].
fn confirm_rounds(s: &str) -> Result<usize, String> {
    in_range(s, "confirmation rounds", 0, limits::MAX_TRIALS)
}

/// Seconds to wait for a quiet machine: 0 ..= [`limits::MAX_WAIT_QUIET_S`].
fn wait_quiet(s: &str) -> Result<u64, String> {
    in_range(s, "--wait-quiet seconds", 0, limits::MAX_WAIT_QUIET_S).map(|v| v as u64)
}

/// Warm-up runs per cell: 0 ..= [`limits::MAX_WARMUP`].
fn warmup(s: &str) -> Result<usize, String> {
    in_range(s, "warm-ups", 0, limits::MAX_WARMUP)
}

/// The machine's hardware threads (1 when unknown).
pub fn hardware_threads() -> usize {
    std::thread::available_parallelism().map_or(1, |n| n.get())
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::CommandFactory;

    #[test]
    fn the_command_line_definition_is_consistent() {
        Cli::command().debug_assert();
    }

    #[test]
    fn zero_and_negative_counts_are_rejected_naming_the_range() {
        assert_eq!(
            resolution("0"),
            Err("resolution must be between 4 and 400, not 0".to_owned())
        );
        assert!(cores("-3").unwrap_err().contains("between 1 and 1024"));
        assert!(
            cores("x")
                .unwrap_err()
                .contains("'x' is not a whole number")
        );
        assert_eq!(cores("12"), Ok(12));
    }

    #[test]
    fn counts_beyond_their_documented_maximum_are_rejected() {
        assert_eq!(cores("1024"), Ok(1024));
        assert!(cores("1025").unwrap_err().contains("between 1 and 1024"));
        assert!(cores("18446744073709551615").is_err());
        assert!(cores("99999999999999999999999").is_err());
        assert!(particles("100000001").is_err());
        assert!(chunks("0").is_err() && steps("1000000001").is_err());
        assert!(resolution("3").is_err() && resolution("401").is_err());
        assert_eq!(resolution("40"), Ok(40));
        assert!(t_end("0").is_err() && t_end("-1").is_err() && t_end("NaN").is_err());
        assert!(t_end("inf").is_err() && t_end("100.5").is_err());
        assert_eq!(t_end("0.77"), Ok(0.77));
    }
}
