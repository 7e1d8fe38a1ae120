//! The coverage test: do the sweep's 95 % intervals contain the truth 95 % of the time?
//!
//! Simulated sweeps on fake timings: a group of eight cells with known true times (`seq` 1 s,
//! the others 0.5–2 s), run in the order [`schedule::order`] gives (shuffled rounds, or cell
//! after cell), each run's time the cell's true time × the machine's state when it ran ×
//! independent log-normal noise (σ = 5 %). The machine's state follows three scenarios over the
//! sweep's runs: (a) constant; (b) a linear drift to 20 % slower by the end; (c) a step of 10 %
//! in the middle. For each, thousands of sweeps; the share of (sweep, cell) pairs whose
//! speedup interval ([`summarize::speedup`]) contains the true ratio is the coverage.
//!
//! With rounds, drift and steps hit a cell and the round's `seq` alike, so their ratio keeps
//! the truth; cell after cell, `seq` runs first and every later cell inherits the machine's
//! change: the intervals stop covering, which is why rounds are the default. Run with
//! `cargo test --profile ci coverage -- --nocapture` to see the table.

use super::schedule::{self, Schedule};
use crate::results::intervals;
use crate::results::key::{Group, test_group};
use crate::results::rows::Phase;
use sph_solver::scene::splitmix::SplitMix64;
use sph_solver::sph::neighbors::NeighborMode;

/// Sweeps simulated per (scenario, schedule, rounds).
const SWEEPS: usize = 2000;
/// The true times of the group's cells, seconds; the first is `seq`.
const TRUE_S: [f64; 8] = [1.0, 0.5, 0.55, 0.6, 0.8, 1.0, 1.2, 2.0];
/// The noise of one run: σ of its logarithm.
const SIGMA: f64 = 0.05;

/// How the machine changes over a sweep: its slowdown at `t` ∈ [0, 1), the run's place in
/// the sweep.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Machine {
    Steady,
    Drift,
    Step,
}

impl Machine {
    fn factor(self, t: f64) -> f64 {
        match self {
            Machine::Steady => 1.0,
            Machine::Drift => 1.0 + 0.2 * t,
            Machine::Step if t < 0.5 => 1.0,
            Machine::Step => 1.1,
        }
    }
}

/// A standard normal draw (Box–Muller).
fn normal(rng: &mut SplitMix64) -> f64 {
    let u = 1.0 - rng.next_f64();
    let v = rng.next_f64();
    (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
}

/// Coverage of the speedup intervals, and of the mean-time intervals, over [`SWEEPS`] sweeps.
fn coverage(machine: Machine, schedule: Schedule, rounds: usize) -> (f64, f64) {
    let group: Group = test_group(NeighborMode::AllPairs);
    let cells: Vec<usize> = (0..TRUE_S.len()).collect();
    let (mut speedups, mut means, mut pairs) = (0usize, 0usize, 0usize);
    for sweep in 0..SWEEPS {
        let seed = 0x5eed ^ (sweep as u64) << 8 ^ rounds as u64;
        let order = schedule::order(schedule, &cells, rounds, seed, &group, Phase::Grid);
        let mut rng = SplitMix64::new(seed.wrapping_mul(0x9e37_79b9_7f4a_7c15));
        let mut times: Vec<Vec<(usize, f64)>> = vec![Vec::new(); cells.len()];
        for (k, run) in order.iter().enumerate() {
            let t = k as f64 / order.len() as f64;
            let noise = (SIGMA * normal(&mut rng)).exp();
            times[run.cell].push((run.round, TRUE_S[run.cell] * machine.factor(t) * noise));
        }
        for cell in 1..cells.len() {
            let truth = TRUE_S[0] / TRUE_S[cell];
            let ratio = intervals::paired_ratio(&times[0], &times[cell]).expect("rounds");
            let interval = ratio.interval.expect("three rounds or more");
            speedups += usize::from(interval.contains(truth));
            let walls: Vec<f64> = times[cell].iter().map(|&(_, w)| w).collect();
            let mean = intervals::mean_interval(&walls).expect("three rounds or more");
            // The noise's median is 1: the typical time is the true time.
            means += usize::from(mean.contains(TRUE_S[cell]));
            pairs += 1;
        }
    }
    (speedups as f64 / pairs as f64, means as f64 / pairs as f64)
}

#[test]
fn nominal_95_percent_intervals_cover_the_truth_with_rounds_and_not_cell_after_cell() {
    let mut table = String::from(
        "scenario     schedule  rounds  speedup coverage  mean coverage (steady only)\n",
    );
    for (machine, name) in [
        (Machine::Steady, "(a) noise"),
        (Machine::Drift, "(b) drift"),
        (Machine::Step, "(c) step"),
    ] {
        for rounds in [3, 5, 10] {
            let (rounds_cover, mean_cover) = coverage(machine, Schedule::Rounds, rounds);
            let (cells_cover, _) = coverage(machine, Schedule::Cells, rounds);
            table.push_str(&format!(
                "{name:<12} rounds    {rounds:>6}  {:>15.1} %  {}\n\
                 {name:<12} cells     {rounds:>6}  {:>15.1} %\n",
                100.0 * rounds_cover,
                if machine == Machine::Steady {
                    format!("{:.1} %", 100.0 * mean_cover)
                } else {
                    "-".to_owned()
                },
                100.0 * cells_cover,
            ));
            let (want, what) = match machine {
                Machine::Steady => (0.93, "independent noise"),
                _ => (0.90, "a changing machine"),
            };
            assert!(
                rounds_cover >= want,
                "rounds cover {rounds_cover} < {want} under {what}:\n{table}"
            );
            if machine == Machine::Steady {
                assert!(
                    mean_cover >= 0.93,
                    "mean intervals cover {mean_cover}:\n{table}"
                );
            } else {
                // Cell after cell, the machine's change lands in the comparison: the same bar
                // is missed.
                assert!(
                    cells_cover < want,
                    "cells covered {cells_cover} under {what}:\n{table}"
                );
            }
        }
    }
    println!("{table}");
}
