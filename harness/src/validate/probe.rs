//! What the validation measures of a running dam break: the surge front and the residual
//! column at the wall, sampled every [`SAMPLE_INTERVAL_S`] of simulated time.
//!
//! - front: x_front = the largest x of any fluid particle, Z = x_front / a;
//! - column: h = the largest y of the fluid particles within 2 dx of the left wall (x < 2 dx;
//!   the wall's inner face is x = 0), H = h / (2a);
//! - times: T = t √(2g/a) for the front, τ = t √(g/a) for the column.
//!
//! [`Probe`] is a [`run::Observer`](crate::run::Observer) of a run in one-step segments: after
//! each step, for every multiple k · 0.01 s that the step's end reached or passed and that has
//! no sample yet, it records the state at that step's end with its actual time (so a sample's
//! t is the first step end at or after k · 0.01 s); it also records the initial state (t = 0)
//! and the final one (the run's end, T ≥ 3.4).

use std::ops::ControlFlow;

use crate::clock::Elapsed;
use crate::run::Observer;
use sph_solver::models::wcsph::params::{COLUMN_WIDTH, WcParams};
use sph_solver::solver::Simulation;

/// Simulated time between samples, s.
pub const SAMPLE_INTERVAL_S: f64 = 0.01;

/// The dimensionless scales of the dam break: a = [`COLUMN_WIDTH`] and g from the constants.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Scales {
    /// Column width a, m.
    pub a: f64,
    /// Gravity's magnitude g, m/s².
    pub g: f64,
    /// Particle spacing dx, m (the column is measured within 2 dx of the wall).
    pub dx: f64,
}

impl Scales {
    /// The scales of a `wcsph` run with constants `prm`.
    pub fn of(prm: &WcParams) -> Scales {
        Scales {
            a: COLUMN_WIDTH,
            g: -prm.gravity.y,
            dx: prm.dx,
        }
    }

    /// T = t √(2g/a) of time `t_s` (s).
    pub fn front_time(&self, t_s: f64) -> f64 {
        t_s * (2.0 * self.g / self.a).sqrt()
    }

    /// τ = t √(g/a) of time `t_s` (s).
    pub fn column_time(&self, t_s: f64) -> f64 {
        t_s * (self.g / self.a).sqrt()
    }

    /// The simulated time, s, at which the front's time T reaches `front_time`.
    pub fn time_of_front_time(&self, front_time: f64) -> f64 {
        front_time / (2.0 * self.g / self.a).sqrt()
    }
}

/// The front and the column at one moment.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sample {
    /// Simulated time t, s.
    pub t_s: f64,
    /// The front's position x_front, m.
    pub front_m: f64,
    /// The column's height at the wall h, m.
    pub column_m: f64,
}

/// The front x_front of `sim`: the largest x of its fluid particles, m (0 without fluid).
pub fn front(sim: &Simulation) -> f64 {
    sim.state.x[..sim.fluid()]
        .iter()
        .copied()
        .fold(0.0, f64::max)
}

/// The column height h of `sim`: the largest y of the fluid particles with x < 2 dx, m (0 when
/// none is that close to the wall).
pub fn column_height(sim: &Simulation, dx: f64) -> f64 {
    let fluid = sim.fluid();
    let near = 2.0 * dx;
    let (x, y) = (&sim.state.x[..fluid], &sim.state.y[..fluid]);
    x.iter()
        .zip(y)
        .filter(|(x, _)| **x < near)
        .map(|(_, y)| *y)
        .fold(0.0, f64::max)
}

/// Samples a run (see the module docs) and adds up the time its steps took. Run it with
/// segments of one step.
#[derive(Debug, Clone)]
pub struct Probe {
    dx: f64,
    t_end_s: f64,
    /// The next multiple of [`SAMPLE_INTERVAL_S`] to record.
    next: usize,
    /// The samples so far, in time order.
    pub samples: Vec<Sample>,
    /// Wall and CPU time of the steps so far, s.
    pub elapsed: Elapsed,
}

impl Probe {
    /// A probe of `sim` (at t = 0, recorded now) for a run that ends at `t_end_s`, measuring
    /// the column within 2 `dx` of the wall.
    pub fn new(sim: &Simulation, dx: f64, t_end_s: f64) -> Probe {
        let mut probe = Probe {
            dx,
            t_end_s,
            next: 1,
            samples: Vec::new(),
            elapsed: Elapsed {
                wall_s: 0.0,
                cpu_s: 0.0,
                foreign: None,
            },
        };
        probe.record(sim);
        probe
    }

    fn record(&mut self, sim: &Simulation) {
        self.samples.push(Sample {
            t_s: sim.time_s,
            front_m: front(sim),
            column_m: column_height(sim, self.dx),
        });
    }

    /// Records `sim` as the rules in the module docs say.
    pub fn observe(&mut self, sim: &Simulation) {
        while self.next as f64 * SAMPLE_INTERVAL_S <= sim.time_s {
            self.record(sim);
            self.next += 1;
        }
        let last = self.samples.last().map_or(f64::NEG_INFINITY, |s| s.t_s);
        if sim.time_s >= self.t_end_s && sim.time_s > last {
            self.record(sim);
        }
    }
}

impl Observer for Probe {
    fn segment(&mut self, sim: &Simulation, elapsed: Elapsed) -> ControlFlow<()> {
        self.elapsed.wall_s += elapsed.wall_s;
        self.elapsed.cpu_s += elapsed.cpu_s;
        self.observe(sim);
        ControlFlow::Continue(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use sph_solver::models::wcsph::scene::{self, Fill};
    use sph_solver::sph::neighbors::NeighborMode;

    fn dam(resolution: usize) -> (WcParams, Simulation) {
        let (prm, state) = scene::build(Fill::DamBreak, resolution).unwrap();
        let sim = Simulation::new(prm, scene::domain(), state, NeighborMode::Grid);
        (prm, sim)
    }

    #[test]
    fn the_initial_column_is_a_wide_and_2a_high_up_to_half_a_spacing() {
        let (prm, sim) = dam(10);
        assert!((front(&sim) - 0.95).abs() < 1e-12);
        assert!((column_height(&sim, prm.dx) - 1.95).abs() < 1e-12);
        // Wall particles (x < 0, up to 2.5a high) are not fluid.
        assert!(sim.state.y[prm.fluid..].iter().any(|&y| y > 2.0));
    }

    #[test]
    fn dimensionless_times_follow_martin_and_moyce() {
        let s = Scales {
            a: 1.0,
            g: 8.0,
            dx: 0.1,
        };
        assert_eq!(s.front_time(0.5), 2.0);
        assert_eq!(s.column_time(0.5), 0.5 * 8f64.sqrt());
        assert_eq!(s.time_of_front_time(2.0), 0.5);
    }

    #[test]
    fn samples_are_taken_at_the_first_step_end_at_or_after_each_hundredth_and_at_the_end() {
        let (prm, mut sim) = dam(4);
        let mut probe = Probe::new(&sim, prm.dx, 0.035);
        for t in [0.004, 0.0099, 0.0101, 0.012, 0.0305, 0.036] {
            sim.time_s = t;
            probe.observe(&sim);
        }
        let times: Vec<f64> = probe.samples.iter().map(|s| s.t_s).collect();
        // 0.0305 passed both 0.02 and 0.03: two samples of that state.
        assert_eq!(times, [0.0, 0.0101, 0.0305, 0.0305, 0.036]);
        // A step that ends exactly on a hundredth and at the end records it once.
        sim.time_s = 0.0;
        let mut exact = Probe::new(&sim, prm.dx, 0.01);
        sim.time_s = 0.01;
        exact.observe(&sim);
        assert_eq!(exact.samples.len(), 2);
    }
}
