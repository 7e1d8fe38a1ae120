//! `bench-sph speedup`: a strategy against `seq`, stepped in turn in one process
//! ([`crate::run::paired`]), for a speedup and an efficiency that a drifting machine affects
//! alike on both sides.

use anyhow::bail;
use clap::Args;
use serde::Serialize;

use crate::checksum::checksum_hex;
use crate::models::Preset;
use crate::output::console;
use crate::run::paired::{PairedTimes, run_paired};
use crate::simd::SimdPath;
use crate::sph::neighbors::{NeighborMode, SumOrder};
use crate::topology::Pin;

/// Options of `speedup`.
#[derive(Debug, Clone, Args)]
#[command(mut_args(super::parallel::strategy_required(
    "Parallel strategy to compare with seq (see `bench-sph list`)"
)))]
pub struct SpeedupArgs {
    /// The scene: preset, N, neighbour search, seed, initial state.
    #[command(flatten)]
    pub scene: super::scene::SceneArgs,
    /// Number of steps each copy runs.
    #[arg(long, default_value_t = 100, value_parser = super::steps)]
    pub steps: usize,
    /// Order of the sums over neighbours, as `simulate --order`.
    #[arg(long, default_value = "index", value_parser = super::values::order())]
    pub order: SumOrder,
    /// How the compared strategy runs: strategy, worker threads, chunks.
    #[command(flatten)]
    pub parallel: super::parallel::ParallelArgs,
    /// Print one JSON object instead of text.
    #[arg(long)]
    pub json: bool,
}

/// The spread of the step-by-step speedups.
#[derive(Debug, Serialize, PartialEq)]
struct Spread {
    min: f64,
    q1: f64,
    median: f64,
    q3: f64,
    max: f64,
}

/// What `speedup --json` prints.
#[derive(Debug, Serialize)]
struct Report {
    preset: Preset,
    neighbors: NeighborMode,
    order: SumOrder,
    strategy: String,
    cores: usize,
    chunks: Option<usize>,
    n: usize,
    steps: usize,
    /// `seq`'s steps, summed.
    seq_s: f64,
    /// The strategy's steps, summed.
    strategy_s: f64,
    /// `seq_s / strategy_s`.
    speedup: f64,
    /// `speedup / cores`.
    efficiency: f64,
    /// Of each step's `seq` time over the strategy's.
    step_speedup: Spread,
    /// More threads than the machine's hardware threads: the speedup is not one of `cores`
    /// cores.
    oversubscribed: bool,
    checksum: String,
    simd: SimdPath,
    pin: Pin,
}

/// Runs `speedup`.
pub fn run(args: &SpeedupArgs) -> anyhow::Result<()> {
    let (mut sim, n) = args.scene.simulation(args.order)?;
    let mut seq_sim = sim.clone();
    let config = args.parallel.config()?;
    let strategy = args.parallel.strategy;
    let times = run_paired(&mut seq_sim, &mut sim, strategy, &config, args.steps)?;
    let (checksum, seq_checksum) = (checksum_hex(&sim.state), checksum_hex(&seq_sim.state));
    if checksum != seq_checksum {
        bail!(
            "{} ended with checksum {checksum}, seq with {seq_checksum}: the strategy changed \
             the results, so no speedup is reported",
            strategy.info().name
        );
    }
    let info = strategy.info();
    let cores = info.effective_cores(config.cores);
    let (seq_s, strategy_s) = (times.seq_s.iter().sum(), times.strategy_s.iter().sum());
    let speedup = seq_s / strategy_s;
    let report = Report {
        preset: args.scene.preset,
        neighbors: args.scene.neighbors,
        order: sim.sum_order(),
        strategy: info.name.to_owned(),
        cores,
        chunks: info.effective_chunks(args.parallel.chunks),
        n,
        steps: sim.steps_done,
        seq_s,
        strategy_s,
        speedup,
        efficiency: speedup / cores as f64,
        step_speedup: spread(&times),
        oversubscribed: cores > super::hardware_threads(),
        checksum,
        simd: sim.simd(),
        pin: args.parallel.pin,
    };
    if report.oversubscribed {
        console::warn(&format!(
            "warning: {cores} threads on {} hardware threads (oversubscribed): this is not a \
             {cores}-core speedup",
            super::hardware_threads()
        ));
    }
    print_report(&report, args.json)
}

/// The spread of each step's speedup (`seq`'s time over the strategy's); quartiles by the
/// nearest rank.
fn spread(times: &PairedTimes) -> Spread {
    let mut ratios: Vec<f64> = times
        .seq_s
        .iter()
        .zip(&times.strategy_s)
        .map(|(s, p)| s / p)
        .collect();
    ratios.sort_by(f64::total_cmp);
    let at = |q: f64| ratios[((ratios.len() - 1) as f64 * q).round() as usize];
    Spread {
        min: at(0.0),
        q1: at(0.25),
        median: at(0.5),
        q3: at(0.75),
        max: at(1.0),
    }
}

fn print_report(r: &Report, json: bool) -> anyhow::Result<()> {
    use super::simulate::say;
    if json {
        return say(&serde_json::to_string(r)?);
    }
    let chunks = r.chunks.map_or_else(|| "n/a".to_owned(), |c| c.to_string());
    say(&format!(
        "preset {}, {} neighbours, N = {}, {} steps; {} (cores {}, chunks {chunks}) against seq, \
         a step of each in turn; simd {}, pin {}",
        r.preset, r.neighbors, r.n, r.steps, r.strategy, r.cores, r.simd, r.pin
    ))?;
    if r.order == SumOrder::Cell {
        say("sums in cell order: not the sources' bits (same bits on every strategy)")?;
    }
    say(&format!(
        "seq {:.4} s, {} {:.4} s: speedup {:.3}, efficiency {:.3}",
        r.seq_s, r.strategy, r.strategy_s, r.speedup, r.efficiency
    ))?;
    let s = &r.step_speedup;
    say(&format!(
        "speedup step by step: median {:.3} (quartiles {:.3}-{:.3}, range {:.3}-{:.3})",
        s.median, s.q1, s.q3, s.min, s.max
    ))?;
    say(&format!("checksum {} (both)", r.checksum))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_spread_is_of_each_steps_ratio_by_nearest_rank() {
        let times = PairedTimes {
            seq_s: vec![2.0, 3.0, 1.0, 4.0, 10.0],
            strategy_s: vec![1.0, 1.0, 1.0, 1.0, 1.0],
        };
        let s = spread(&times);
        assert_eq!(
            s,
            Spread {
                min: 1.0,
                q1: 2.0,
                median: 3.0,
                q3: 4.0,
                max: 10.0
            }
        );
        let one = PairedTimes {
            seq_s: vec![3.0],
            strategy_s: vec![2.0],
        };
        assert_eq!(spread(&one).median, 1.5);
    }
}
