//! A group's input, built once and cloned for every run, and the short `seq` run that
//! estimates a sweep's time.
//!
//! Each run simulates the whole dam break from the group's initial state on a fresh
//! [`Simulation`](sph_solver::solver::Simulation), through [`run_timed`] (the timed region is the
//! step loop only).

use super::plan::{Cell, Group};
use super::rows::Measured;
use crate::run::run_timed;
use sph_solver::checksum::checksum_hex;
use sph_solver::scene::Scene;

/// The initial state of a group, built once and cloned for every run.
pub struct GroupInput {
    /// The group.
    pub group: Group,
    scene: Scene,
}

impl GroupInput {
    /// The group's initial state for jitter seed `seed`.
    pub fn new(group: Group, seed: u64) -> GroupInput {
        let scene = Scene::dam_break(group.preset, group.n, seed)
            .unwrap_or_else(|e| panic!("no memory for {} particles: {e}", group.n));
        GroupInput { group, scene }
    }

    /// One whole run of `cell` from the initial state: its times and final checksum.
    pub fn run(&self, cell: &Cell) -> Result<Measured, String> {
        self.run_steps(cell, self.group.steps)
    }

    /// `steps` steps of `cell` from the initial state.
    fn run_steps(&self, cell: &Cell, steps: usize) -> Result<Measured, String> {
        let mut sim = self.scene.clone().simulate(self.group.neighbors);
        let load1 = crate::contention::load1();
        let placement =
            crate::placement::placement(cell.pin).map_err(|e| one_line(&format!("{e:#}")))?;
        let config = cell.config().placed(placement);
        let elapsed = run_timed(&mut sim, cell.strategy, &config, steps)
            .map_err(|e| one_line(&format!("{:#}", anyhow::Error::new(e))))?;
        Ok(Measured {
            elapsed,
            load1,
            checksum: checksum_hex(&sim.state),
        })
    }
}

/// A message on one line (CSV fields and resume's line-based repair rely on it).
fn one_line(s: &str) -> String {
    s.split_whitespace().collect::<Vec<_>>().join(" ")
}

/// The most particles the estimate simulates, per neighbour search: it must take well under
/// a second whatever N the sweep asks for.
const CALIBRATION_N_ALL_PAIRS: usize = 4000;
/// See [`CALIBRATION_N_ALL_PAIRS`].
const CALIBRATION_N_GRID: usize = 200_000;

/// Seconds one `seq` run of `group` takes, estimated from a short timed run of at most
/// 4000 (all-pairs, `CALIBRATION_N_ALL_PAIRS`) or 200 000 (grid, `CALIBRATION_N_GRID`) particles,
/// scaled by (N / sample)² or N / sample: one step, then doubling the steps until a run
/// takes 50 ms or covers all steps. NaN when the run fails (the sweep will then report the
/// failure properly).
pub fn calibrate(group: Group, seed: u64) -> f64 {
    let (cap, exponent) = match group.neighbors {
        sph_solver::sph::neighbors::NeighborMode::AllPairs => (CALIBRATION_N_ALL_PAIRS, 2),
        sph_solver::sph::neighbors::NeighborMode::Grid => (CALIBRATION_N_GRID, 1),
    };
    let sample = Group {
        n: group.n.min(cap),
        ..group
    };
    let scale = (group.n as f64 / sample.n as f64).powi(exponent);
    let input = GroupInput::new(sample, seed);
    let seq = Cell::reference(sample);
    let mut steps = 1;
    loop {
        let Ok(m) = input.run_steps(&seq, steps) else {
            return f64::NAN;
        };
        if m.elapsed.wall_s >= 0.05 || steps >= group.steps {
            return m.elapsed.wall_s / steps as f64 * group.steps as f64 * scale;
        }
        steps = (steps * 2).min(group.steps);
    }
}
