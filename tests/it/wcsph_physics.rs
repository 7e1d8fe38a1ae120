//! The `wcsph` preset's physics as a whole: a tank at rest stays at rest, and a dam break
//! keeps its mass and its walls.

use bench_sph::models::Physics;
use bench_sph::models::wcsph::scene::{self, Fill};
use bench_sph::run::{RunError, Steps, run_timed, run_timed_steps};
use bench_sph::scene::Scene;
use bench_sph::solver::{Simulation, StepError};
use bench_sph::sph::neighbors::NeighborMode;
use sph_strategies::{Config, StrategyName};

const SEQ: Config = Config::new(1, 1);

/// Steps `sim` with `seq` until `t_end` seconds of simulated time.
fn advance_until(sim: &mut Simulation, t_end: f64) -> Result<(), StepError> {
    let steps = Steps {
        until_s: Some(t_end),
        ..Steps::timed(usize::MAX)
    };
    match run_timed_steps(sim, StrategyName::Seq, &SEQ, steps) {
        Ok(_) => Ok(()),
        Err(RunError::Step(e)) => Err(e),
        Err(e) => panic!("seq runs: {e:#}"),
    }
}

fn run_until(sim: &mut Simulation, t_end: f64) {
    advance_until(sim, t_end).expect("the run stays finite");
}

fn params(sim: &Simulation) -> bench_sph::models::wcsph::params::WcParams {
    match sim.physics {
        Physics::Wcsph(p) => p,
        Physics::Mueller(_) => unreachable!("a tank is wcsph"),
    }
}

#[test]
fn still_water_in_the_tank_stays_still_for_half_a_second() {
    let scene = Scene::tank(Fill::StillWater, 10).unwrap();
    let start = scene.state.clone();
    let mut sim = scene.simulate(NeighborMode::Grid);
    run_until(&mut sim, 0.5);
    let prm = params(&sim);
    let fluid = sim.fluid();
    // Gravity alone would reach 4.9 m/s in 0.5 s; a tank at rest keeps every particle
    // below 1 % of the wave speed sqrt(g · depth) ≈ 3.1 m/s.
    let fastest = (0..fluid)
        .map(|k| sim.state.velocity(k).length())
        .fold(0.0, f64::max);
    assert!(fastest < 0.03, "fastest particle {fastest} m/s");
    // Nobody moved more than a fifth of the spacing.
    let moved = (0..fluid)
        .map(|k| (sim.state.x[k] - start.x[k]).hypot(sim.state.y[k] - start.y[k]))
        .fold(0.0, f64::max);
    assert!(
        moved < 0.2 * prm.dx,
        "a particle moved {moved} m (dx {})",
        prm.dx
    );
    // The density stays hydrostatic to within 0.5 %.
    for k in 0..fluid {
        let gap = (sim.state.rho[k] - start.rho[k]).abs() / start.rho[k];
        assert!(
            gap < 5e-3,
            "particle {k}: density {} from {}",
            sim.state.rho[k],
            start.rho[k]
        );
    }
}

#[test]
fn the_dam_break_keeps_its_fluid_inside_the_walls_and_the_walls_fixed() {
    let scene = Scene::tank(Fill::DamBreak, 12).unwrap();
    let walls_before: Vec<(f64, f64)> = (scene.fluid()..scene.state.len())
        .map(|k| (scene.state.x[k], scene.state.y[k]))
        .collect();
    let mut sim = scene.simulate(NeighborMode::Grid);
    run_until(&mut sim, 0.4);
    let fluid = sim.fluid();
    let d = scene::domain();
    for k in 0..fluid {
        let (x, y) = (sim.state.x[k], sim.state.y[k]);
        assert!(
            (0.0..=d.width).contains(&x) && y >= 0.0,
            "particle {k} left the tank: ({x}, {y})"
        );
    }
    let walls_after: Vec<(f64, f64)> = (fluid..sim.state.len())
        .map(|k| (sim.state.x[k], sim.state.y[k]))
        .collect();
    assert_eq!(walls_before, walls_after);
    // By 0.4 s the surge has travelled more than a column width (Z > 2).
    let front = sim.state.x[..fluid]
        .iter()
        .cloned()
        .fold(f64::MIN, f64::max);
    assert!(front > 2.0, "front at {front} m");
}

#[test]
fn a_non_finite_density_stops_the_run_in_the_step_it_appears() {
    let mut sim = Scene::tank(Fill::DamBreak, 6)
        .unwrap()
        .simulate(NeighborMode::Grid);
    sim.state.rho[5] = f64::NAN;
    let err = run_timed(&mut sim, StrategyName::Seq, &SEQ, 3).unwrap_err();
    assert!(
        matches!(err, RunError::Step(StepError::Diverged { step: 1, .. })),
        "{err}"
    );
}

#[test]
fn fluid_that_splashes_out_of_the_open_tank_ends_the_run_with_an_error() {
    let mut sim = Scene::tank(Fill::DamBreak, 6)
        .unwrap()
        .simulate(NeighborMode::Grid);
    let err = advance_until(&mut sim, 3.0).unwrap_err();
    assert!(matches!(err, StepError::Unphysical { .. }), "{err}");
    assert!(err.to_string().contains("left the tank"), "{err}");
    // It happened after the surge hit the far wall, not before.
    assert!(sim.time_s > 0.8, "at {} s", sim.time_s);
}
