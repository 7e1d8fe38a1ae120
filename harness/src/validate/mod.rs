//! `bench-sph validate`: the `wcsph` dam break against Martin & Moyce (1952), the collapse of
//! a square water column (n² = 2).
//!
//! The pipeline: [`data`] (the experiment's tables, shipped as CSV) → a run of the dam break
//! to T = 3.4 with the grid search, sampled every 0.01 s by [`probe`] → [`verdict`] (pure:
//! each point's error and three verdicts) → [`export`] (CSV) and `sph_report::plot::validation` (PNG), and
//! [`summary`] (the printed table and the JSON object). The run goes through
//! [`run::run_steps`](crate::run::run_steps) like every other, so any strategy gives the same
//! bits as `seq`; the time reported is the step loop's (sampling excluded).

pub mod data;
pub mod export;
pub mod probe;
pub mod summary;
pub mod verdict;

use anyhow::Context;
use sph_strategies::{Config, StrategyName};

use crate::clock::Elapsed;
use crate::limits;
use crate::run::{Steps, run_steps};
use data::{Experiment, Point};
use probe::{Probe, Sample, Scales};
use sph_solver::models::wcsph::scene::{self, Fill};
use sph_solver::solver::Simulation;
use sph_solver::sph::neighbors::NeighborMode;
use verdict::Outcome;

/// The front time T = t √(2g/a) at which the run ends (the experiment's front data ends at
/// T = 3.33).
pub const T_END: f64 = 3.4;

/// The default resolution R = a / dx.
pub const DEFAULT_RESOLUTION: usize = 40;

/// A validation run and its comparison with the experiment.
#[derive(Debug, Clone)]
pub struct Validation {
    /// R = a / dx.
    pub resolution: usize,
    /// Fluid particles (2R²).
    pub fluid: usize,
    /// Fixed wall particles.
    pub walls: usize,
    /// The strategy that ran the passes.
    pub strategy: StrategyName,
    /// Its cores and chunks, as asked for.
    pub config: Config,
    /// Steps run.
    pub steps: usize,
    /// Simulated time at the end, s.
    pub simulated_s: f64,
    /// Wall and CPU time of the step loop, s (sampling excluded).
    pub elapsed: Elapsed,
    /// The run's scales (a, g, dx).
    pub scales: Scales,
    /// The samples, in time order (t = 0, every 0.01 s, the end).
    pub samples: Vec<Sample>,
    /// The experiment.
    pub experiment: Experiment,
    /// The simulated front Z(T), in time order.
    pub front: Vec<Point>,
    /// The simulated column H(τ), in time order.
    pub column: Vec<Point>,
    /// The comparison.
    pub outcome: Outcome,
}

/// Runs the dam break at resolution R (`resolution`, within
/// [`RESOLUTIONS`](sph_solver::models::wcsph::params::RESOLUTIONS)) with `strategy` on `config` until
/// T ≥ [`T_END`], and compares it with the experiment.
pub fn validate(
    resolution: usize,
    strategy: StrategyName,
    config: &Config,
) -> anyhow::Result<Validation> {
    let experiment = data::experiment().context("the shipped experiment data is broken")?;
    let (prm, state) = scene::build(Fill::DamBreak, resolution)
        .with_context(|| format!("no memory for the dam break at resolution {resolution}"))?;
    let walls = state.len() - prm.fluid;
    let scales = Scales::of(&prm);
    let t_end_s = scales.time_of_front_time(T_END);
    let mut sim = Simulation::new(prm, scene::domain(), state, NeighborMode::Grid);
    let mut probe = Probe::new(&sim, prm.dx, t_end_s);
    let steps = Steps {
        total: limits::MAX_STEPS,
        every: 1,
        warmup: 0,
        until_s: Some(t_end_s),
    };
    run_steps(&mut sim, strategy, config, steps, &mut probe)?;
    let front: Vec<Point> = probe
        .samples
        .iter()
        .map(|s| Point {
            time: scales.front_time(s.t_s),
            value: s.front_m / scales.a,
        })
        .collect();
    let column: Vec<Point> = probe
        .samples
        .iter()
        .map(|s| Point {
            time: scales.column_time(s.t_s),
            value: s.column_m / (2.0 * scales.a),
        })
        .collect();
    let outcome = verdict::evaluate(&experiment, &front, &column);
    Ok(Validation {
        resolution,
        fluid: prm.fluid,
        walls,
        strategy,
        config: *config,
        steps: sim.steps_done,
        simulated_s: sim.time_s,
        elapsed: probe.elapsed,
        scales,
        samples: probe.samples,
        experiment,
        front,
        column,
        outcome,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_coarse_run_reaches_t_3_4_with_a_sample_every_hundredth_of_a_second() {
        let config = Config::new(1, 1);
        let v = validate(8, StrategyName::Seq, &config).unwrap();
        assert_eq!((v.fluid, v.samples[0].t_s), (128, 0.0));
        let last = v.samples.last().unwrap().t_s;
        assert_eq!(last, v.simulated_s);
        assert!(v.scales.front_time(last) >= T_END);
        let (a, b) = (v.samples.len() - 2, v.samples.len() - 1);
        assert!(v.samples[b].t_s > v.samples[a].t_s);
        for (k, s) in v.samples[..b].iter().enumerate() {
            let due = k as f64 * probe::SAMPLE_INTERVAL_S;
            assert!(
                s.t_s >= due && s.t_s < due + 0.001,
                "sample {k} at {}",
                s.t_s
            );
        }
        assert_eq!(v.front.len(), v.samples.len());
    }
}
