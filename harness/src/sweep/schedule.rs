//! The order of a group's timed runs: shuffled rounds (the default), or cell after cell.
//!
//! - **Rounds** (`--schedule rounds`): `--trials K` makes K rounds; in each round every cell of
//!   the group, its `seq` reference included, runs once, in an order shuffled afresh for the
//!   round. Slow drift of the machine and sudden steps (a frequency change, a neighbour's job)
//!   then hit every cell alike, and the round's `seq` run is the partner of each of its other
//!   runs in a paired speedup ([`crate::results::intervals`]).
//! - **Cells** (`--schedule cells`, for comparison): the order of the first versions — the
//!   `seq` cell's K trials, then each cell's K trials back to back, in plan order. Round r of a
//!   cell is then its r-th trial, which ran minutes away from `seq`'s r-th: drift lands in the
//!   comparison (the coverage test shows it).
//!
//! The shuffle is Fisher–Yates driven by [`SplitMix64`] seeded with the sweep's `--seed`, the
//! group, the phase and the round ([`round_seed`]), so a sweep's order is reproduced from its
//! `meta.json`, and a resumed sweep runs the rounds it had planned.

use serde::{Deserialize, Serialize};

use crate::results::key::Group;
use crate::results::rows::Phase;
use sph_solver::checksum::fingerprint;
use sph_solver::scene::splitmix::SplitMix64;

pub use crate::results::params::Schedule;

/// One timed run of a cell.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct Run {
    /// The cell, as its position in the plan.
    pub cell: usize,
    /// The round, from 1 (under `cells`: the cell's trial number).
    pub round: usize,
    /// The run's place in its round, from 1 (under `cells`: the cell's place in the group).
    pub position: usize,
}

/// The seed of the shuffle of `round` of `group`'s `phase` in a sweep seeded `seed`.
pub fn round_seed(seed: u64, group: &Group, phase: Phase, round: usize) -> u64 {
    let key = format!("{}/{}/{round}", group.slug(), phase.as_str());
    seed ^ fingerprint(key.as_bytes())
}

/// The timed runs of `cells` (plan positions, the group's `seq` first) over `rounds` rounds,
/// in the order they run.
pub fn order(
    schedule: Schedule,
    cells: &[usize],
    rounds: usize,
    seed: u64,
    group: &Group,
    phase: Phase,
) -> Vec<Run> {
    let mut runs = Vec::with_capacity(cells.len() * rounds);
    match schedule {
        Schedule::Cells => {
            for (place, &cell) in cells.iter().enumerate() {
                runs.extend((1..=rounds).map(|round| Run {
                    cell,
                    round,
                    position: place + 1,
                }));
            }
        }
        Schedule::Rounds => {
            for round in 1..=rounds {
                let mut shuffled = cells.to_vec();
                shuffle(
                    &mut shuffled,
                    &mut SplitMix64::new(round_seed(seed, group, phase, round)),
                );
                runs.extend(shuffled.iter().enumerate().map(|(place, &cell)| Run {
                    cell,
                    round,
                    position: place + 1,
                }));
            }
        }
    }
    runs
}

/// Fisher–Yates, each index drawn with Lemire's multiply-shift (bias below 2⁻⁴⁰ for the
/// cells a group can hold).
fn shuffle<T>(items: &mut [T], rng: &mut SplitMix64) {
    for i in (1..items.len()).rev() {
        let j = ((u128::from(rng.next_u64()) * (i as u128 + 1)) >> 64) as usize;
        items.swap(i, j);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::results::key::test_group;
    use sph_solver::sph::neighbors::NeighborMode;

    fn group() -> Group {
        test_group(NeighborMode::AllPairs)
    }

    #[test]
    fn every_round_runs_every_cell_once_in_its_own_order() {
        let cells: Vec<usize> = (10..20).collect();
        let runs = order(Schedule::Rounds, &cells, 5, 2019, &group(), Phase::Grid);
        assert_eq!(runs.len(), 50);
        let mut orders = Vec::new();
        for round in 1..=5 {
            let mut of_round: Vec<&Run> = runs.iter().filter(|r| r.round == round).collect();
            assert_eq!(of_round.len(), 10);
            of_round.sort_by_key(|r| r.position);
            assert!(
                of_round
                    .iter()
                    .enumerate()
                    .all(|(i, r)| r.position == i + 1)
            );
            let order: Vec<usize> = of_round.iter().map(|r| r.cell).collect();
            let mut sorted = order.clone();
            sorted.sort_unstable();
            assert_eq!(sorted, cells);
            orders.push(order);
        }
        // Shuffled: not the plan's order, and not the same order every round.
        assert!(orders.iter().any(|o| *o != cells));
        assert!(orders.windows(2).any(|w| w[0] != w[1]));
        // Rounds run one after the other.
        assert!(runs.windows(2).all(|w| w[0].round <= w[1].round));
    }

    #[test]
    fn the_seq_reference_is_not_always_first() {
        let cells: Vec<usize> = (0..8).collect();
        let firsts = (1..=40)
            .filter(|&seed| {
                order(Schedule::Rounds, &cells, 1, seed, &group(), Phase::Grid)[0].cell == 0
            })
            .count();
        assert!(firsts < 20, "seq first in {firsts} of 40 sweeps");
    }

    #[test]
    fn the_order_is_a_function_of_seed_group_phase_and_round() {
        let cells: Vec<usize> = (0..12).collect();
        let a = order(Schedule::Rounds, &cells, 3, 7, &group(), Phase::Grid);
        assert_eq!(
            a,
            order(Schedule::Rounds, &cells, 3, 7, &group(), Phase::Grid)
        );
        assert_ne!(
            a,
            order(Schedule::Rounds, &cells, 3, 8, &group(), Phase::Grid)
        );
        assert_ne!(
            a,
            order(Schedule::Rounds, &cells, 3, 7, &group(), Phase::Confirm)
        );
        let other = test_group(NeighborMode::Grid);
        assert_ne!(
            a,
            order(Schedule::Rounds, &cells, 3, 7, &other, Phase::Grid)
        );
        // More rounds add rounds; they do not reorder the first ones.
        let longer = order(Schedule::Rounds, &cells, 4, 7, &group(), Phase::Grid);
        assert_eq!(longer[..a.len()], a[..]);
    }

    #[test]
    fn the_cells_schedule_runs_each_cells_trials_back_to_back_in_plan_order() {
        let runs = order(Schedule::Cells, &[0, 3, 4], 2, 1, &group(), Phase::Grid);
        let got: Vec<(usize, usize, usize)> =
            runs.iter().map(|r| (r.cell, r.round, r.position)).collect();
        assert_eq!(
            got,
            [
                (0, 1, 1),
                (0, 2, 1),
                (3, 1, 2),
                (3, 2, 2),
                (4, 1, 3),
                (4, 2, 3)
            ]
        );
    }
}
