//! `bench-sph overhead`: what a pass costs each strategy apart from its work
//! ([`crate::run::pass_cost`]), at each core count, with its interval.

use std::time::Duration;

use anyhow::Context;
use clap::Args;
use serde::Serialize;

use crate::output::console;
use crate::results::intervals::ratio;
use crate::run::pass_cost;
use crate::sweep::range::{self, Axis};
use sph_strategies::StrategyName;

/// Options of `overhead`.
#[derive(Debug, Clone, Args)]
pub struct OverheadArgs {
    /// Strategies, comma-separated (see `bench-sph list`) [default: all].
    #[arg(long, value_name = "LIST", value_delimiter = ',', value_parser = super::values::strategy())]
    pub strategies: Vec<StrategyName>,
    /// Worker threads: N, A..B, A..B:S or a comma list [default: 1..the hardware threads].
    #[arg(long, value_name = "RANGE")]
    pub cores: Option<String>,
    /// Work of a pass per thread, in µs (0..=1000): each thread's chunk keeps it busy this long.
    #[arg(long, value_name = "US", default_value_t = 5, value_parser = work_us)]
    pub work_us: u64,
    /// Passes per round (1..=100000).
    #[arg(long, default_value_t = 1000, value_parser = passes)]
    pub passes: u64,
    /// Rounds per cell (3..=100, the fewest that give an interval); the cells take turns
    /// round by round.
    #[arg(long, default_value_t = 10, value_parser = rounds)]
    pub rounds: usize,
    /// Print one JSON object instead of text.
    #[arg(long)]
    pub json: bool,
}

fn work_us(s: &str) -> Result<u64, String> {
    super::in_range(s, "work a pass (µs)", 0, 1000).map(|v| v as u64)
}

fn passes(s: &str) -> Result<u64, String> {
    super::in_range(s, "passes", 1, 100_000).map(|v| v as u64)
}

fn rounds(s: &str) -> Result<usize, String> {
    super::in_range(s, "rounds", crate::results::intervals::MIN_ROUNDS, 100)
}

/// One strategy at one core count.
#[derive(Debug, Serialize)]
struct Cell {
    strategy: &'static str,
    cores: usize,
    /// Typical time a pass, µs: the geometric mean of the rounds' mean times a pass, and its
    /// 95 % interval (as a sweep's cell times).
    pass_us: f64,
    pass_low_us: f64,
    pass_high_us: f64,
    /// `pass_us` less the work a thread: the strategy's cost a pass.
    beyond_work_us: f64,
    /// More threads than the machine's hardware threads.
    oversubscribed: bool,
}

/// What `overhead --json` prints.
#[derive(Debug, Serialize)]
struct Report {
    work_us: u64,
    passes: u64,
    rounds: usize,
    hardware_threads: usize,
    cells: Vec<Cell>,
}

/// Runs `overhead`.
pub fn run(args: &OverheadArgs) -> anyhow::Result<()> {
    let hardware = super::hardware_threads();
    let cores = match &args.cores {
        Some(spec) => {
            range::parse(spec, Axis::Cores).with_context(|| format!("--cores '{spec}'"))?
        }
        None => (1..=hardware).collect(),
    };
    let strategies = if args.strategies.is_empty() {
        StrategyName::ALL.to_vec()
    } else {
        args.strategies.clone()
    };
    // A strategy that runs every pass on the calling thread is measured at one core only.
    let cells: Vec<(StrategyName, usize)> = strategies
        .iter()
        .flat_map(|&s| {
            let mut at: Vec<usize> = cores.iter().map(|&c| s.info().effective_cores(c)).collect();
            at.dedup();
            at.into_iter().map(move |c| (s, c))
        })
        .collect();
    if cores.iter().any(|&c| c > hardware) {
        console::warn(&format!(
            "warning: more threads than the {hardware} hardware threads (oversubscribed): \
             those cells measure threads taking turns on a core"
        ));
    }
    let work = Duration::from_micros(args.work_us);
    // The cells take turns round by round, so that a slow spell of the machine hits all.
    let mut times = vec![Vec::with_capacity(args.rounds); cells.len()];
    for _ in 0..args.rounds {
        for (&(strategy, cores), times) in cells.iter().zip(&mut times) {
            let round = pass_cost::measure(strategy, cores, work, args.passes, 1)
                .with_context(|| format!("{strategy} at {cores} cores"))?;
            times.extend(round);
        }
    }
    let cells = cells
        .iter()
        .zip(&times)
        .map(|(&(strategy, cores), times)| cell(strategy, cores, times, work, hardware))
        .collect();
    let report = Report {
        work_us: args.work_us,
        passes: args.passes,
        rounds: args.rounds,
        hardware_threads: hardware,
        cells,
    };
    print_report(&report, args.json)
}

fn cell(strategy: StrategyName, cores: usize, times: &[f64], work: Duration, hw: usize) -> Cell {
    let us = |s: f64| s * 1e6;
    // Every round's time is positive and finite (a pass takes time), and there are at least
    // `MIN_ROUNDS` of them (the flag's range): the estimate and its interval exist.
    let typical = ratio(times).expect("positive times");
    let interval = typical
        .interval
        .map_or((f64::NAN, f64::NAN), |i| (i.low, i.high));
    Cell {
        strategy: strategy.info().name,
        cores,
        pass_us: us(typical.value),
        pass_low_us: us(interval.0),
        pass_high_us: us(interval.1),
        beyond_work_us: us(typical.value) - us(work.as_secs_f64()),
        oversubscribed: cores > hw,
    }
}

fn print_report(r: &Report, json: bool) -> anyhow::Result<()> {
    use super::simulate::say;
    if json {
        return say(&serde_json::to_string(r)?);
    }
    say(&format!(
        "a pass with {} µs of work a thread, one chunk a thread: typical time a pass (geometric \
         mean over {} rounds of {} passes) and its 95 % interval; beyond the work is the \
         strategy's cost a pass",
        r.work_us, r.rounds, r.passes
    ))?;
    let width = r.cells.iter().map(|c| c.strategy.len()).max().unwrap_or(8);
    say(&format!(
        "{:width$}  cores  {:>26}  beyond the work",
        "strategy", "a pass"
    ))?;
    for c in &r.cells {
        let flag = if c.oversubscribed {
            "  oversubscribed"
        } else {
            ""
        };
        say(&format!(
            "{:width$}  {:>5}  {:>9.2} µs [{:.2}–{:.2}]  {:>9.2} µs{flag}",
            c.strategy, c.cores, c.pass_us, c.pass_low_us, c.pass_high_us, c.beyond_work_us
        ))?;
    }
    Ok(())
}
