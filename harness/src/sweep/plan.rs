//! What a sweep measures: groups of cells, in the order they run.
//!
//! A **group** is one (preset, neighbours, N, steps): the same initial state and the same
//! final checksum for every strategy. For `wcsph`, N is the fluid-particle count 2R² of the
//! resolution R nearest each `--n`
//! ([`wcsph::scene::resolution_for`](sph_solver::models::wcsph::scene::resolution_for)); `--n` values that
//! share a resolution make one group. Each group starts with its **reference cell**, `seq` at
//! 1 core, measured whatever `--strategies` says: its mean is the denominator of speedup and
//! its first run's checksum the one every other run of the group must reproduce. Then, for each
//! other strategy in registry order and each cores value, one cell per chunks value for the
//! strategies that use chunks, and one cell (chunks empty) for those that do not; each of those
//! once per `--pin` placement, side by side (the reference runs unpinned).
//!
//! A **shard** I/K of the plan ([`Plan::shard`], `sweep --shard I/K`) runs the plan's
//! non-reference cells whose position among them is ≡ I−1 (mod K), dealt round-robin in plan
//! order, plus the reference cell of every group it touches: each shard measures its own
//! `seq`, so that its speedups never divide by another node's time. A group with no other cell
//! (a sweep of `seq` alone) goes whole to shard (g mod K) + 1, g its position. Round-robin,
//! not balanced by an estimate of each cell's cost: an estimate is measured, so it would
//! differ from node to node and so would the partition; dealing in plan order spreads each
//! strategy's cores and chunks values over all shards, which balances them well enough.

use sph_strategies::StrategyName;

pub use crate::results::key::{Cell, Group, LabelStyle};
use crate::results::params::SweepParams;
use crate::results::shard::Shard;
use sph_solver::scene::Scene;

/// Every cell of a sweep, grouped, in the order they run.
#[derive(Debug, Clone, PartialEq)]
pub struct Plan {
    /// The groups, in order (presets, then neighbour searches, then N).
    pub groups: Vec<Group>,
    /// The cells, group by group, each group's reference cell first.
    pub cells: Vec<Cell>,
}

impl Plan {
    /// The plan of `params`: the whole plan, or the shard `params.shard` names.
    pub fn new(params: &SweepParams) -> Plan {
        let whole = Plan::whole(params);
        match params.shard {
            Some(shard) => whole.shard(shard),
            None => whole,
        }
    }

    /// The whole plan of `params`, whatever shard they name.
    pub fn whole(params: &SweepParams) -> Plan {
        let mut groups = Vec::new();
        for &preset in &params.presets {
            for &neighbors in &params.neighbors {
                for &n in &params.n {
                    let group = Group {
                        preset,
                        neighbors,
                        n: Scene::dam_break_fluid(preset, n),
                        steps: params.steps,
                    };
                    if !groups.contains(&group) {
                        groups.push(group);
                    }
                }
            }
        }
        let mut cells = Vec::new();
        for &group in &groups {
            cells.push(Cell::reference(group));
            for &strategy in params
                .strategies
                .iter()
                .filter(|&&s| s != StrategyName::Seq)
            {
                for &cores in &params.cores {
                    let chunks: Vec<Option<usize>> = if strategy.info().uses_chunks() {
                        params.chunks.iter().map(|&k| Some(k)).collect()
                    } else {
                        vec![None]
                    };
                    for chunks in chunks {
                        cells.extend(params.pin.iter().map(|&pin| Cell {
                            group,
                            strategy,
                            cores,
                            chunks,
                            pin,
                        }));
                    }
                }
            }
        }
        Plan { groups, cells }
    }
}

impl Plan {
    /// The part of this (whole) plan that `shard` runs (see the module docs), in plan order;
    /// its groups are those it has cells of.
    pub fn shard(&self, shard: Shard) -> Plan {
        let (i, k) = (shard.index - 1, shard.count);
        let mut position = 0;
        let mut mine: Vec<Cell> = Vec::new();
        for (g, group) in self.groups.iter().enumerate() {
            let of_group = self.cells.iter().filter(|c| c.group == *group);
            let mut reference = None;
            let mut taken = Vec::new();
            let mut others = 0;
            for &cell in of_group {
                if cell.is_reference() {
                    reference = Some(cell);
                    continue;
                }
                if position % k == i {
                    taken.push(cell);
                }
                position += 1;
                others += 1;
            }
            let whole_group = others == 0 && g % k == i;
            if !taken.is_empty() || whole_group {
                mine.extend(reference);
                mine.extend(taken);
            }
        }
        Plan {
            groups: self
                .groups
                .iter()
                .copied()
                .filter(|g| mine.iter().any(|c| c.group == *g))
                .collect(),
            cells: mine,
        }
    }

    /// Cells that are not a group's reference.
    pub fn non_reference_cells(&self) -> usize {
        self.cells.iter().filter(|c| !c.is_reference()).count()
    }
}

/// A guess of one run's seconds for `cell`, from the measured seconds of one `seq` run of its
/// group: `seq_run_s` divided by the ideal speedup min(cores, hardware threads).
pub fn estimate_run_s(cell: &Cell, seq_run_s: f64, hardware_threads: usize) -> f64 {
    if cell.is_reference() {
        return seq_run_s;
    }
    seq_run_s / cell.cores.min(hardware_threads).max(1) as f64
}

#[cfg(test)]
mod tests {
    use super::*;
    use sph_solver::models::Preset;
    use sph_solver::sph::neighbors::NeighborMode;

    fn params(strategies: &[StrategyName]) -> SweepParams {
        SweepParams {
            strategies: strategies.to_vec(),
            neighbors: vec![NeighborMode::AllPairs, NeighborMode::Grid],
            cores: vec![1, 2, 4],
            warmup: 1,
            ..SweepParams::small()
        }
    }

    #[test]
    fn every_group_starts_with_seq_at_one_core_even_when_seq_is_not_asked_for() {
        let plan = Plan::new(&params(&[StrategyName::RayonChunks]));
        assert_eq!(plan.groups.len(), 2);
        assert_eq!(plan.cells.len(), 2 * (1 + 3 * 2));
        for group in &plan.groups {
            let first = plan.cells.iter().find(|c| c.group == *group).unwrap();
            assert!(first.is_reference());
            assert_eq!((first.cores, first.chunks), (1, None));
        }
    }

    #[test]
    fn seq_is_measured_once_per_group_whatever_the_cores() {
        let plan = Plan::new(&params(StrategyName::ALL));
        let seqs = plan.cells.iter().filter(|c| c.is_reference()).count();
        assert_eq!(seqs, plan.groups.len());
    }

    #[test]
    fn strategies_without_chunks_get_one_cell_per_cores_value() {
        let plan = Plan::new(&params(StrategyName::ALL));
        for &s in StrategyName::ALL
            .iter()
            .filter(|&&s| s != StrategyName::Seq)
        {
            let cells: Vec<&Cell> = plan.cells.iter().filter(|c| c.strategy == s).collect();
            let per_cores = if s.info().uses_chunks() { 2 } else { 1 };
            assert_eq!(cells.len(), 2 * 3 * per_cores, "{s}");
            assert!(
                cells
                    .iter()
                    .all(|c| c.chunks.is_some() == s.info().uses_chunks())
            );
        }
    }

    #[test]
    fn the_shards_of_a_plan_deal_its_cells_round_robin_and_together_hold_each_exactly_once() {
        let whole = Plan::new(&params(StrategyName::ALL));
        let k = 3;
        let shards: Vec<Plan> = (1..=k)
            .map(|i| whole.shard(Shard::new(i, k).unwrap()))
            .collect();
        let mut others: Vec<Cell> = shards
            .iter()
            .flat_map(|s| s.cells.iter().copied().filter(|c| !c.is_reference()))
            .collect();
        assert_eq!(others.len(), whole.non_reference_cells());
        let unique: std::collections::HashSet<Cell> = others.drain(..).collect();
        assert_eq!(unique.len(), whole.non_reference_cells());
        let sizes: Vec<usize> = shards.iter().map(Plan::non_reference_cells).collect();
        assert!(
            sizes.iter().max().unwrap() - sizes.iter().min().unwrap() <= 1,
            "{sizes:?}"
        );
        for (s, shard) in shards.iter().enumerate() {
            for group in &shard.groups {
                let first = shard.cells.iter().find(|c| c.group == *group).unwrap();
                assert!(first.is_reference(), "shard {} group {group:?}", s + 1);
            }
        }
        // Round-robin in plan order: shard 1 has the 1st, 4th, … non-reference cells.
        let order: Vec<Cell> = whole
            .cells
            .iter()
            .copied()
            .filter(|c| !c.is_reference())
            .collect();
        let first: Vec<Cell> = shards[0]
            .cells
            .iter()
            .copied()
            .filter(|c| !c.is_reference())
            .collect();
        assert_eq!(first, order.iter().copied().step_by(k).collect::<Vec<_>>());
    }

    #[test]
    fn a_seq_only_plan_gives_whole_groups_to_shards_in_turn_and_one_shard_is_the_plan() {
        let whole = Plan::new(&params(&[StrategyName::Seq]));
        assert_eq!(whole.non_reference_cells(), 0);
        let one = whole.shard(Shard::new(1, 2).unwrap());
        let two = whole.shard(Shard::new(2, 2).unwrap());
        assert_eq!((one.cells.len(), two.cells.len()), (1, 1));
        assert_ne!(one.groups, two.groups);
        assert!(whole.shard(Shard::new(1, 3).unwrap()).cells.len() == 1);
        assert!(whole.shard(Shard::new(3, 3).unwrap()).cells.is_empty());
        let all = Plan::new(&params(StrategyName::ALL));
        assert_eq!(all.shard(Shard::new(1, 1).unwrap()), all);
    }

    #[test]
    fn particles_per_chunk_is_the_largest_balanced_chunk() {
        let group = Group {
            preset: Preset::Seed,
            neighbors: NeighborMode::Grid,
            n: 1000,
            steps: 1,
        };
        let cell = |chunks| Cell {
            group,
            strategy: StrategyName::RayonChunks,
            cores: 2,
            chunks,
            pin: crate::topology::Pin::None,
        };
        assert_eq!(cell(Some(10)).particles_per_chunk(), Some(100));
        assert_eq!(cell(Some(333)).particles_per_chunk(), Some(4));
        assert_eq!(cell(Some(5000)).particles_per_chunk(), Some(1));
        assert_eq!(cell(None).particles_per_chunk(), None);
    }

    #[test]
    fn the_estimate_assumes_ideal_speedup_up_to_the_hardware_threads() {
        let plan = Plan::new(&params(StrategyName::ALL));
        let at = |cores| {
            *plan
                .cells
                .iter()
                .find(|c| c.strategy == StrategyName::RayonIter && c.cores == cores)
                .unwrap()
        };
        assert_eq!(estimate_run_s(&plan.cells[0], 2.0, 2), 2.0);
        assert_eq!(estimate_run_s(&at(2), 2.0, 2), 1.0);
        assert_eq!(estimate_run_s(&at(4), 2.0, 2), 1.0);
        assert!(at(4).oversubscribed(2) && !at(2).oversubscribed(2));
    }
}
