//! `bench-sph overhead`: what a pass costs each strategy apart from its work
//! ([`crate::run::pass_cost`]), at each core count, with its interval.

use std::time::Duration;

use anyhow::Context;
use clap::Args;
use serde::Serialize;

use crate::output::console;
use crate::run::pass_cost::{self, CostRow};
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
    #[arg(long, default_value_t = crate::sweep::beside::PASS_PASSES, value_parser = passes)]
    pub passes: u64,
    /// Rounds per cell (3..=100, the fewest that give an interval); the cells take turns
    /// round by round.
    #[arg(long, default_value_t = crate::sweep::beside::PASS_ROUNDS, value_parser = rounds)]
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

/// What `overhead --json` prints.
#[derive(Debug, Serialize)]
struct Report {
    work_us: u64,
    passes: u64,
    rounds: usize,
    hardware_threads: usize,
    cells: Vec<CostRow>,
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
    if cores.iter().any(|&c| c > hardware) {
        console::warn(&format!(
            "warning: more threads than the {hardware} hardware threads (oversubscribed): \
             those cells measure threads taking turns on a core"
        ));
    }
    let cells = pass_cost::cells(&strategies, &cores);
    let work = Duration::from_micros(args.work_us);
    let cells = pass_cost::table(&cells, work, args.passes, args.rounds, hardware, || false)?
        .expect("never asked to stop");
    let report = Report {
        work_us: args.work_us,
        passes: args.passes,
        rounds: args.rounds,
        hardware_threads: hardware,
        cells,
    };
    print_report(&report, args.json)
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
