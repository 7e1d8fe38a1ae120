//! One step of the solver checked against values computed here, by hand, straight from the
//! formulas of the step (density with self term, forces over j != i, symplectic Euler, wall
//! clamps), with plain scalar f64 arithmetic in the sources' evaluation order.

use bench_sph::models::{Preset, mueller::params::Params};
use bench_sph::run::run_timed;
use bench_sph::solver::Simulation;
use bench_sph::sph::neighbors::NeighborMode;
use bench_sph::sph::state::{Domain, State};
use sph_strategies::{Config, StrategyName};

const TANK: Domain = Domain {
    width: 1200.0,
    height: 900.0,
};

fn step(preset: Preset, state: State, mode: NeighborMode, steps: usize) -> State {
    let mut sim = Simulation::new(preset.params(), TANK, state, mode);
    run_timed(&mut sim, StrategyName::Seq, &Config::new(1, 1), steps).expect("step runs");
    sim.state
}

fn state(p: &[(f64, f64, f64, f64)]) -> State {
    State::from_kinematics(
        p.iter().map(|q| q.0).collect(),
        p.iter().map(|q| q.1).collect(),
        p.iter().map(|q| q.2).collect(),
        p.iter().map(|q| q.3).collect(),
    )
}

/// The step written out longhand for a handful of particles.
fn hand_step(prm: &Params, s: &State) -> State {
    let n = s.len();
    let (h, hsq) = (16.0f64, 256.0f64);
    let mut rho = vec![0.0f64; n];
    let mut p = vec![0.0f64; n];
    for i in 0..n {
        let mut sum = 0.0;
        for j in 0..n {
            let (dx, dy) = (s.x[j] - s.x[i], s.y[j] - s.y[i]);
            let r2 = dx * dx + dy * dy;
            if r2 < hsq {
                let u = hsq - r2;
                sum += (65.0 * prm.poly6) * ((u * u) * u);
            }
        }
        rho[i] = sum;
        p[i] = 2000.0 * (sum - 1000.0);
    }
    let mut out = s.clone();
    for i in 0..n {
        let (mut fpx, mut fpy, mut fvx, mut fvy) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
        for j in 0..n {
            if j == i {
                continue;
            }
            let (dx, dy) = (s.x[j] - s.x[i], s.y[j] - s.y[i]);
            let r = (dx * dx + dy * dy).sqrt();
            if r < h {
                if r != 0.0 {
                    fpx += (((((-dx / r) * 65.0) * (p[i] + p[j])) / (2.0 * rho[j]))
                        * prm.spiky_grad)
                        * ((h - r) * (h - r));
                    fpy += (((((-dy / r) * 65.0) * (p[i] + p[j])) / (2.0 * rho[j]))
                        * prm.spiky_grad)
                        * ((h - r) * (h - r));
                }
                fvx += (((250.0 * 65.0) * (s.vx[j] - s.vx[i])) / rho[j]) * prm.visc_lap * (h - r);
                fvy += (((250.0 * 65.0) * (s.vy[j] - s.vy[i])) / rho[j]) * prm.visc_lap * (h - r);
            }
        }
        let fx = (fpx + fvx) + 0.0 * rho[i];
        let fy = (fpy + fvy) + prm.gravity.y * rho[i];
        let (vx, vy) = if preset_of(prm) == Preset::Seed {
            (
                s.vx[i] + prm.dt * (fx / rho[i]),
                s.vy[i] + prm.dt * (fy / rho[i]),
            )
        } else {
            (
                s.vx[i] + (prm.dt * fx) / rho[i],
                s.vy[i] + (prm.dt * fy) / rho[i],
            )
        };
        let (x, y) = (s.x[i] + prm.dt * vx, s.y[i] + prm.dt * vy);
        (out.x[i], out.y[i], out.vx[i], out.vy[i]) = (x, y, vx, vy);
        (out.fx[i], out.fy[i], out.rho[i], out.p[i]) = (fx, fy, rho[i], p[i]);
    }
    out
}

fn preset_of(prm: &Params) -> Preset {
    if *prm == Preset::Seed.params() {
        Preset::Seed
    } else {
        Preset::Cpp
    }
}

fn assert_same_bits(a: &State, b: &State) {
    for (name, (fa, fb)) in bench_sph::sph::state::FIELD_NAMES
        .iter()
        .zip(a.fields().iter().zip(b.fields()))
    {
        for (i, (va, vb)) in fa.iter().zip(fb.iter()).enumerate() {
            assert_eq!(va.to_bits(), vb.to_bits(), "{name}[{i}]: {va:e} != {vb:e}");
        }
    }
}

#[test]
fn three_particles_get_the_hand_computed_step_in_both_presets_and_both_searches() {
    // Three particles within reach of one another, at distances that are not round numbers,
    // with velocities so that viscosity contributes, far from the walls.
    let init = state(&[
        (600.25, 450.5, 3.0, -2.0),
        (609.75, 455.125, -1.5, 0.5),
        (603.5, 441.0625, 0.25, 4.0),
    ]);
    for preset in Preset::MUELLER {
        let expected = hand_step(&preset.params(), &init);
        assert!(
            expected.fx.iter().all(|f| *f != 0.0),
            "pressure and viscosity both act"
        );
        for mode in NeighborMode::ALL {
            assert_same_bits(&step(preset, init.clone(), mode, 1), &expected);
        }
    }
}

#[test]
fn a_lone_particle_falls_by_exact_symplectic_euler_steps() {
    for preset in Preset::MUELLER {
        let prm = preset.params();
        let mut expected = state(&[(600.0, 700.0, 0.0, 0.0)]);
        for _ in 0..50 {
            expected = hand_step(&prm, &expected);
        }
        let got = step(
            preset,
            state(&[(600.0, 700.0, 0.0, 0.0)]),
            NeighborMode::AllPairs,
            50,
        );
        assert_same_bits(&got, &expected);
        // It only ever feels its own density and gravity.
        assert_eq!(got.rho[0], prm.mass_poly6 * (256.0f64 * 256.0 * 256.0));
        assert_eq!(got.fx[0], 0.0);
        assert!(got.vy[0] < 0.0 && got.y[0] < 700.0 && got.x[0] == 600.0);
    }
}

#[test]
fn a_particle_crossing_the_floor_is_put_back_at_eps_with_damped_velocity() {
    for (preset, damping) in [(Preset::Seed, -1.0), (Preset::Cpp, -0.5)] {
        let prm = preset.params();
        let before = state(&[(600.0, 16.5, 0.0, -2000.0)]);
        let free = hand_step(&prm, &before); // the unclamped Euler step
        assert!(free.y[0] < 16.0);
        let got = step(preset, before, NeighborMode::AllPairs, 1);
        assert_eq!(got.y[0], 16.0);
        assert_eq!(got.vy[0], free.vy[0] * damping);
        assert!(got.vy[0] > 0.0, "the particle now moves up");
    }
}

#[test]
fn every_wall_clamps_its_own_component_only() {
    let prm = Preset::Cpp.params();
    // Left, right, ceiling, and the lower-left corner; far enough apart not to interact.
    let before = state(&[
        (10.0, 300.0, -5.0, 0.0),
        (1190.0, 300.0, 5.0, 0.0),
        (600.0, 895.0, 0.0, 4000.0),
        (3.0, 2.0, -7.0, -3000.0),
    ]);
    let free = hand_step(&prm, &before);
    let got = step(Preset::Cpp, before, NeighborMode::Grid, 1);
    assert_eq!((got.x[0], got.vx[0]), (16.0, free.vx[0] * -0.5));
    assert_eq!((got.y[0], got.vy[0]), (free.y[0], free.vy[0]));
    assert_eq!((got.x[1], got.vx[1]), (1184.0, free.vx[1] * -0.5));
    assert_eq!((got.y[2], got.vy[2]), (884.0, free.vy[2] * -0.5));
    assert_eq!((got.x[2], got.vx[2]), (free.x[2], free.vx[2]));
    assert_eq!((got.x[3], got.y[3]), (16.0, 16.0));
    assert_eq!(
        (got.vx[3], got.vy[3]),
        (free.vx[3] * -0.5, free.vy[3] * -0.5)
    );
}

#[test]
fn two_particles_at_the_same_point_feel_viscosity_but_no_pressure_and_stay_finite() {
    for preset in Preset::MUELLER {
        let prm = preset.params();
        let init = state(&[(500.0, 500.0, 10.0, 0.0), (500.0, 500.0, -10.0, 6.0)]);
        let got = step(preset, init.clone(), NeighborMode::Grid, 1);
        let expected = hand_step(&prm, &init);
        assert_same_bits(&got, &expected);
        assert!(got.first_non_finite().is_none());
        // Viscosity pulls the two velocities together: equal and opposite x forces.
        assert!(got.fx[0] < 0.0 && got.fx[1] > 0.0);
        assert_eq!(got.fx[0], -got.fx[1]);
    }
}

#[test]
fn a_pair_at_exactly_the_kernel_radius_does_not_interact() {
    // r2 = 256 exactly: outside both the density (r2 < HSQ) and force (r < H) tests.
    let init = state(&[(500.0, 500.0, 0.0, 0.0), (516.0, 500.0, 0.0, 0.0)]);
    let got = step(Preset::Seed, init, NeighborMode::AllPairs, 1);
    assert_eq!(got.fx, vec![0.0, 0.0]);
    assert_eq!(got.rho[0], got.rho[1]);
}

#[test]
fn neighbours_taken_two_at_a_time_give_the_hand_computed_step_on_every_simd_path() {
    use bench_sph::simd::SimdPath;
    // Particle 0 has five neighbours, one of them at its own point (r = 0: the pair in the
    // same four lanes as another is left to the one-at-a-time code), and the others an odd or
    // even number; distances and velocities are not round numbers.
    let init = state(&[
        (500.0, 500.0, 3.0, -2.0),
        (500.0, 500.0, -1.5, 0.5),
        (507.3, 503.1, 0.25, 4.0),
        (495.25, 509.0, -6.0, 1.0),
        (502.0, 488.5, 2.0, 2.5),
        (511.5, 497.75, -0.5, -3.0),
    ]);
    for preset in Preset::MUELLER {
        let expected = hand_step(&preset.params(), &init);
        assert!(expected.first_non_finite().is_none());
        for mode in NeighborMode::ALL {
            for path in SimdPath::available() {
                let mut sim = Simulation::new(preset.params(), TANK, init.clone(), mode)
                    .with_simd(path)
                    .expect("an available path");
                run_timed(&mut sim, StrategyName::Seq, &Config::new(1, 1), 1).expect("step runs");
                assert_same_bits(&sim.state, &expected);
            }
        }
    }
}
