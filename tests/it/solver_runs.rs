//! Whole runs of the solver: the two neighbour searches agree, the reference run stays finite
//! and inside the walls, and a diverging run stops with an error naming step and particle.

use bench_sph::models::Preset;
use bench_sph::models::mueller;
use bench_sph::run::{RunError, run_timed};
use bench_sph::scene::Scene;
use bench_sph::solver::{Simulation, StepError};
use bench_sph::sph::neighbors::{GridKeys, NeighborMode, SumOrder};
use bench_sph::sph::state::{Domain, FIELD_NAMES, State};
use sph_strategies::{Config, StrategyName};

const SEQ: Config = Config::new(1, 1);

fn run(preset: Preset, n: usize, steps: usize, mode: NeighborMode) -> State {
    let mut sim = Scene::dam_break(preset, n, 2019).unwrap().simulate(mode);
    run_timed(&mut sim, StrategyName::Seq, &SEQ, steps).expect("run completes");
    sim.state
}

/// Per field: max |a - b| <= tol * max |b| over all particles.
fn max_relative_gap(a: &State, b: &State) -> Vec<(&'static str, f64)> {
    FIELD_NAMES
        .iter()
        .zip(a.fields().iter().zip(b.fields()))
        .map(|(name, (fa, fb))| {
            let gap = fa
                .iter()
                .zip(fb.iter())
                .map(|(x, y)| (x - y).abs())
                .fold(0.0, f64::max);
            let scale = fb.iter().map(|y| y.abs()).fold(0.0, f64::max);
            (*name, if scale == 0.0 { gap } else { gap / scale })
        })
        .collect()
}

#[test]
fn grid_agrees_with_all_pairs_to_1e_9_after_10_steps_for_every_preset() {
    for preset in Preset::ALL {
        let all_pairs = run(preset, 1000, 10, NeighborMode::AllPairs);
        let grid = run(preset, 1000, 10, NeighborMode::Grid);
        for (field, gap) in max_relative_gap(&grid, &all_pairs) {
            assert!(gap <= 1e-9, "{preset} {field}: relative gap {gap:e}");
        }
    }
}

#[test]
fn cell_order_agrees_with_index_order_to_1e_9_after_10_steps_and_differs_in_bits_later() {
    let cell_order = |preset, steps| {
        let mut sim = Scene::dam_break(preset, 1000, 2019)
            .unwrap()
            .simulate(NeighborMode::Grid)
            .with_sum_order(SumOrder::Cell)
            .unwrap();
        run_timed(&mut sim, StrategyName::Seq, &SEQ, steps).expect("run completes");
        sim.state
    };
    for preset in Preset::ALL {
        let (index, cell) = (
            run(preset, 1000, 10, NeighborMode::Grid),
            cell_order(preset, 10),
        );
        for (field, gap) in max_relative_gap(&cell, &index) {
            assert!(gap <= 1e-9, "{preset} {field}: relative gap {gap:e}");
        }
        // Once the dam has collapsed the numbers no longer follow the cells, and the sums
        // round differently.
        let steps = 200;
        assert_ne!(
            cell_order(preset, steps),
            run(preset, 1000, steps, NeighborMode::Grid),
            "{preset}"
        );
    }
}

#[test]
fn all_pairs_has_no_cell_order() {
    let sim = Scene::dam_break(Preset::Seed, 10, 1)
        .unwrap()
        .simulate(NeighborMode::AllPairs);
    assert!(sim.with_sum_order(SumOrder::Cell).is_err());
}

#[test]
fn neighbour_lists_of_any_width_give_the_same_bits() {
    // Width 2 holds one neighbour: nearly every particle overflows and is searched again by
    // the passes that read the lists.
    // In cell order the passes' own search must visit the same order as the lists do.
    for preset in Preset::ALL {
        for (mode, keys, order) in [
            (NeighborMode::AllPairs, GridKeys::Index, SumOrder::Index),
            (NeighborMode::Grid, GridKeys::Index, SumOrder::Index),
            (NeighborMode::Grid, GridKeys::Position, SumOrder::Index),
            (NeighborMode::Grid, GridKeys::Index, SumOrder::Cell),
            (NeighborMode::Grid, GridKeys::Position, SumOrder::Cell),
        ] {
            let run_with = |width: Option<usize>| {
                let sim = Scene::dam_break(preset, 700, 2019)
                    .unwrap()
                    .simulate(mode)
                    .with_grid_keys(keys)
                    .with_sum_order(order)
                    .unwrap();
                let mut sim = match width {
                    Some(w) => sim.with_list_slots(w),
                    None => sim,
                };
                run_timed(&mut sim, StrategyName::Seq, &SEQ, 150).expect("run completes");
                sim.state
            };
            let what = format!("{preset} {mode} {keys:?} keys, order {order}");
            assert_eq!(run_with(Some(2)), run_with(None), "{what}");
        }
    }
}

#[test]
fn grid_visits_neighbours_in_index_order_so_it_gives_the_same_bits_as_all_pairs() {
    for preset in Preset::ALL {
        let all_pairs = run(preset, 700, 200, NeighborMode::AllPairs);
        for keys in [GridKeys::Index, GridKeys::Position] {
            let mut sim = Scene::dam_break(preset, 700, 2019)
                .unwrap()
                .simulate(NeighborMode::Grid)
                .with_grid_keys(keys);
            run_timed(&mut sim, StrategyName::Seq, &SEQ, 200).expect("run completes");
            assert_eq!(sim.state, all_pairs, "{preset} {keys:?}");
        }
    }
}

#[test]
fn small_runs_list_grid_neighbours_by_index_and_large_ones_by_position() {
    let keys = |n| {
        Scene::dam_break(Preset::Seed, n, 1)
            .unwrap()
            .simulate(NeighborMode::Grid)
            .grid_keys()
    };
    assert_eq!(keys(1000), Some(GridKeys::Index));
    assert_eq!(keys(10_000), Some(GridKeys::Position));
}

/// One step of `state` in a 1200 × 900 tank with the seed constants: with the grid and its
/// lists in `keys`, or with all-pairs (`None`).
fn one_step(state: State, grid_keys: Option<GridKeys>) -> State {
    let domain = Domain {
        width: 1200.0,
        height: 900.0,
    };
    let params = Preset::Seed.params();
    let mut sim = match grid_keys {
        Some(keys) => {
            Simulation::new(params, domain, state, NeighborMode::Grid).with_grid_keys(keys)
        }
        None => Simulation::new(params, domain, state, NeighborMode::AllPairs),
    };
    run_timed(&mut sim, StrategyName::Seq, &SEQ, 1).expect("step completes");
    sim.state
}

#[test]
fn a_crowd_beyond_the_grids_buffers_gives_the_same_bits_as_all_pairs() {
    // 150 particles within a few px, numbered in scrambled order: more candidates than the
    // grid's scratch holds (128) and more hits than the neighbour-list slots hold, so the
    // crowded-block and fallback paths run; plus a sparse line of particles (and some outside
    // the tank) whose rows have few candidates.
    let mut x = Vec::new();
    let mut y = Vec::new();
    for k in 0..150u64 {
        let scrambled = (k * 7919) % 150;
        x.push(600.0 + (scrambled % 12) as f64 * 0.37);
        y.push(400.0 + (scrambled / 12) as f64 * 0.41);
    }
    for k in 0..60 {
        x.push(-20.0 + 21.5 * k as f64);
        y.push(if k % 7 == 0 {
            905.0
        } else {
            10.0 + (k % 5) as f64 * 9.0
        });
    }
    let n = x.len();
    let state = State::from_kinematics(x, y, vec![0.0; n], vec![0.0; n]);
    let all_pairs = one_step(state.clone(), None);
    assert!(all_pairs.first_non_finite().is_none());
    for keys in [GridKeys::Index, GridKeys::Position] {
        let grid = one_step(state.clone(), Some(keys));
        assert_eq!(grid, all_pairs, "{keys:?}");
    }
}

#[test]
fn cell_order_gives_the_same_bits_with_either_key_in_a_crowded_block() {
    // 200 particles across a cell boundary, numbered in scrambled order: their row holds more
    // candidates than the grid's scratch holds (128), and each particle's hits come from two
    // cells, whose candidate order is not their index order.
    let (x, y): (Vec<f64>, Vec<f64>) = (0..200u64)
        .map(|k| {
            let s = (k * 7919) % 200;
            (600.0 + (s % 20) as f64 * 0.8, 400.0 + (s / 20) as f64 * 0.9)
        })
        .unzip();
    let n = x.len();
    let state = State::from_kinematics(x, y, vec![0.0; n], vec![0.0; n]);
    let domain = Domain {
        width: 1200.0,
        height: 900.0,
    };
    let cell_order = |keys| {
        let sim = Simulation::new(
            Preset::Seed.params(),
            domain,
            state.clone(),
            NeighborMode::Grid,
        );
        let mut sim = sim
            .with_grid_keys(keys)
            .with_sum_order(SumOrder::Cell)
            .unwrap();
        run_timed(&mut sim, StrategyName::Seq, &SEQ, 1).expect("step completes");
        sim.state
    };
    let by_position = cell_order(GridKeys::Position);
    assert_eq!(cell_order(GridKeys::Index), by_position);
    assert_ne!(
        by_position,
        one_step(state, None),
        "cell order sums in another order"
    );
}

#[test]
fn neighbours_behind_a_pile_of_more_candidates_than_a_grid_key_counts_give_all_pairs_bits() {
    // 300 particles piled in one cell row, and a few in the row above, out of the pile's
    // reach: their lists would fit, but a grid with position keys names their neighbours by
    // keys past 255 (the pile comes first among their candidates), so the force pass searches
    // again.
    let (mut x, mut y): (Vec<f64>, Vec<f64>) = (0..300)
        .map(|k| (600.0 + (k % 20) as f64 * 0.2, 401.0 + (k / 20) as f64 * 0.2))
        .unzip();
    x.extend([601.0, 603.0, 605.0, 607.0]);
    y.extend([425.0, 426.0, 427.0, 425.5]);
    let n = x.len();
    let state = State::from_kinematics(x, y, vec![0.0; n], vec![0.0; n]);
    let grid = one_step(state.clone(), Some(GridKeys::Position));
    let all_pairs = one_step(state, None);
    assert_eq!(grid, all_pairs);
    assert!(grid.first_non_finite().is_none());
}

#[test]
fn the_reference_run_stays_finite_and_inside_the_walls() {
    let domain = mueller::scene::domain(Preset::Seed, 1000);
    let s = run(Preset::Seed, 1000, 1000, NeighborMode::AllPairs);
    assert_eq!(s.first_non_finite(), None);
    let eps = 16.0;
    for i in 0..s.len() {
        assert!(
            (eps..=domain.width - eps).contains(&s.x[i]),
            "particle {i} x = {}",
            s.x[i]
        );
        assert!(
            (eps..=domain.height - eps).contains(&s.y[i]),
            "particle {i} y = {}",
            s.y[i]
        );
    }
    // The dam has collapsed: particles reached the floor and spread to the right.
    assert!(s.y.iter().cloned().fold(f64::MAX, f64::min) < 40.0);
    assert!(s.x.iter().cloned().fold(0.0, f64::max) > 900.0);
}

#[test]
fn a_run_past_the_layout_capacity_grows_the_tank_and_stays_inside_it() {
    let n = 3000; // more than the seed layout's 1406
    let domain = mueller::scene::domain(Preset::Seed, n);
    assert!(domain.width > 1200.0);
    let s = run(Preset::Seed, n, 20, NeighborMode::Grid);
    assert_eq!(s.first_non_finite(), None);
    assert!(
        s.x.iter()
            .all(|&x| (16.0..=domain.width - 16.0).contains(&x))
    );
}

#[test]
fn a_diverging_run_stops_with_the_step_and_particle_that_went_non_finite() {
    // Opposite velocities near f64::MAX: the viscosity difference overflows to infinity.
    let init = State::from_kinematics(
        vec![500.0, 505.0],
        vec![500.0, 500.0],
        vec![0.0, 0.0],
        vec![1e308, -1e308],
    );
    let mut sim = Simulation::new(
        Preset::Seed.params(),
        Domain {
            width: 1200.0,
            height: 900.0,
        },
        init,
        NeighborMode::AllPairs,
    );
    let err = run_timed(&mut sim, StrategyName::Seq, &SEQ, 5).unwrap_err();
    match err {
        RunError::Step(StepError::Diverged {
            step,
            particle,
            field,
        }) => {
            assert_eq!((step, particle), (1, 0));
            assert!(FIELD_NAMES.contains(&field));
        }
        other => panic!("expected divergence, got {other}"),
    }
    assert_eq!(sim.steps_done, 1);
}

#[test]
fn a_large_run_checked_in_parallel_blocks_stops_at_the_same_step_and_particle() {
    // 80 000 particles: the divergence check runs on the executor in blocks. The same two
    // overflowing particles as above, placed last, away from the dam.
    let n = 80_000;
    let domain = mueller::scene::domain(Preset::Seed, n);
    let mut init = mueller::scene::initial_state(Preset::Seed, n, 1);
    let last = n - 2;
    (init.x[last], init.x[last + 1]) = (domain.width - 100.0, domain.width - 95.0);
    (init.y[last], init.y[last + 1]) = (100.0, 100.0);
    (init.vy[last], init.vy[last + 1]) = (1e308, -1e308);
    for (strategy, cores) in [(StrategyName::Seq, 1), (StrategyName::CrossbeamPool, 2)] {
        let mut sim = Simulation::new(
            Preset::Seed.params(),
            domain,
            init.clone(),
            NeighborMode::Grid,
        );
        let config = Config::new(cores, 7);
        match run_timed(&mut sim, strategy, &config, 5).unwrap_err() {
            RunError::Step(StepError::Diverged { step, particle, .. }) => {
                assert_eq!((step, particle), (1, last), "{strategy}");
            }
            other => panic!("{strategy}: expected divergence, got {other}"),
        }
    }
}
