//! What a sweep measures: groups of cells, in the order they run.
//!
//! A **group** is one (preset, neighbours, N, steps): the same initial state and the same
//! final checksum for every strategy. For `wcsph`, N is the fluid-particle count 2R² of the
//! resolution R nearest each `--n` ([`tank::resolution_for`]); `--n` values that share a
//! resolution make one group. Each group starts with its **reference cell**, `seq` at
//! 1 core, measured whatever `--strategies` says: its mean is the denominator of speedup and
//! its first run's checksum the one every other run of the group must reproduce. Then, for each
//! other strategy in registry order and each cores value, one cell per chunks value for the
//! strategies that use chunks, and one cell (chunks empty) for those that do not.

use sph_strategies::StrategyName;

pub use crate::results::key::{Cell, Group, LabelStyle};
use crate::results::params::SweepParams;
use crate::scene::tank;
use crate::sph::params::Preset;

/// Every cell of a sweep, grouped, in the order they run.
#[derive(Debug, Clone, PartialEq)]
pub struct Plan {
    /// The groups, in order (presets, then neighbour searches, then N).
    pub groups: Vec<Group>,
    /// The cells, group by group, each group's reference cell first.
    pub cells: Vec<Cell>,
}

impl Plan {
    /// The plan of `params`.
    pub fn new(params: &SweepParams) -> Plan {
        let mut groups = Vec::new();
        for &preset in &params.presets {
            for &neighbors in &params.neighbors {
                for &n in &params.n {
                    let group = Group {
                        preset,
                        neighbors,
                        n: particles(preset, n),
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
                    let cell = |chunks| Cell {
                        group,
                        strategy,
                        cores,
                        chunks,
                    };
                    if strategy.info().uses_chunks() {
                        cells.extend(params.chunks.iter().map(|&k| cell(Some(k))));
                    } else {
                        cells.push(cell(None));
                    }
                }
            }
        }
        Plan { groups, cells }
    }
}

/// The particles a group of `preset` has for `--n` `n`: `n`, or for `wcsph` the fluid
/// particles of the nearest resolution.
pub fn particles(preset: Preset, n: usize) -> usize {
    match preset {
        Preset::Wcsph => tank::dam_break_particles(tank::resolution_for(n)),
        _ => n,
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
    use crate::sph::neighbors::NeighborMode;
    use crate::sph::params::Preset;

    fn params(strategies: &[StrategyName]) -> SweepParams {
        SweepParams {
            strategies: strategies.to_vec(),
            presets: vec![Preset::Seed],
            neighbors: vec![NeighborMode::AllPairs, NeighborMode::Grid],
            n: vec![60],
            steps: 3,
            cores: vec![1, 2, 4],
            chunks: vec![2, 5],
            trials: 2,
            warmup: 1,
            seed: 1,
            simd: None,
            fake_timings: None,
            fake_contention: None,
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
