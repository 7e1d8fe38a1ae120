//! What a sweep measures: groups of cells, in the order they run.
//!
//! A **group** is one (preset, neighbours, N, steps): the same initial state and the same
//! final checksum for every strategy. Each group starts with its **reference cell**, `seq` at
//! 1 core, measured whatever `--strategies` says: its mean is the denominator of speedup and
//! its first run's checksum the one every other run of the group must reproduce. Then, for each
//! other strategy in registry order and each cores value, one cell per chunks value for the
//! strategies that use chunks, and one cell (chunks empty) for those that do not.

use sph_strategies::{Config, StrategyName};

use super::params::SweepParams;
use crate::sph::neighbors::NeighborMode;
use crate::sph::params::Preset;

/// The keys shared by every cell of a group.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Group {
    /// Constants and integration order.
    pub preset: Preset,
    /// Neighbour search.
    pub neighbors: NeighborMode,
    /// Particles.
    pub n: usize,
    /// Steps per run.
    pub steps: usize,
}

/// How a group is named in text: the sweep's console and the report word it differently, and
/// each keeps its wording (both are compared byte for byte by users' scripts and the tests).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LabelStyle {
    /// As the sweep prints it: `preset seed, all-pairs, N = 1000, 1000 steps`.
    Sweep,
    /// As the report prints it: `seed preset, all-pairs, N = 1000, 1000 steps`.
    Report,
}

impl Group {
    /// The group in words, worded as `style` says (see [`LabelStyle`]).
    pub fn label(&self, style: LabelStyle) -> String {
        let preset = match style {
            LabelStyle::Sweep => format!("preset {}", self.preset),
            LabelStyle::Report => format!("{} preset", self.preset),
        };
        format!(
            "{preset}, {}, N = {}, {}",
            self.neighbors,
            self.n,
            super::console::plural(self.steps, "step", "steps")
        )
    }

    /// A file-name part, e.g. `seed-all-pairs-n1000-s1000`.
    pub fn slug(&self) -> String {
        format!(
            "{}-{}-n{}-s{}",
            self.preset, self.neighbors, self.n, self.steps
        )
    }
}

/// One configuration to measure, and the key of its rows in the results CSVs: what
/// `--resume` and the report match on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Cell {
    /// The group it belongs to.
    pub group: Group,
    /// The strategy.
    pub strategy: StrategyName,
    /// Worker threads (1 for `seq`).
    pub cores: usize,
    /// Requested chunks per pass; `None` for strategies without a chunks parameter.
    pub chunks: Option<usize>,
}

impl Cell {
    /// Whether this is its group's `seq` reference cell.
    pub fn is_reference(&self) -> bool {
        self.strategy == StrategyName::Seq
    }

    /// The strategy configuration (strategies without chunks ignore `chunks`).
    pub fn config(&self) -> Config {
        Config {
            cores: self.cores,
            chunks: self.chunks.unwrap_or(1),
        }
    }

    /// Particles in the largest of the `min(chunks, n)` balanced chunks: `ceil(n / min(chunks, n))`.
    pub fn particles_per_chunk(&self) -> Option<usize> {
        let n = self.group.n;
        self.chunks.map(|k| n.div_ceil(k.min(n)))
    }

    /// Whether the cell asks for more threads than the machine has.
    pub fn oversubscribed(&self, hardware_threads: usize) -> bool {
        self.cores > hardware_threads
    }

    /// The text that seeds the cell's bootstrap streams ([`super::bootstrap::rng_for`]): frozen,
    /// so that a display change never changes a results file (`rayon-chunks, 2 cores, 10
    /// chunks`, `seq, 1 core`).
    pub fn stream_key(&self) -> String {
        let cores = if self.cores == 1 { "core" } else { "cores" };
        match self.chunks {
            Some(k) => format!("{}, {} {cores}, {k} chunks", self.strategy, self.cores),
            None => format!("{}, {} {cores}", self.strategy, self.cores),
        }
    }

    /// E.g. `rayon-chunks, 2 cores, 10 chunks`: today the same text as the frozen
    /// [`stream_key`](Self::stream_key); a display change goes here, never there.
    pub fn label(&self) -> String {
        self.stream_key()
    }

    /// The cell and its group, e.g. `rayon-chunks, 2 cores, 10 chunks (preset seed,
    /// all-pairs, N = 1000, 300 steps)`: how warnings name a cell.
    pub fn label_with_group(&self) -> String {
        format!("{} ({})", self.label(), self.group.label(LabelStyle::Sweep))
    }
}

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
                    groups.push(Group {
                        preset,
                        neighbors,
                        n,
                        steps: params.steps,
                    });
                }
            }
        }
        let mut cells = Vec::new();
        for &group in &groups {
            cells.push(Cell {
                group,
                strategy: StrategyName::Seq,
                cores: 1,
                chunks: None,
            });
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
                    if strategy.info().uses_chunks {
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
            let per_cores = if s.info().uses_chunks { 2 } else { 1 };
            assert_eq!(cells.len(), 2 * 3 * per_cores, "{s}");
            assert!(
                cells
                    .iter()
                    .all(|c| c.chunks.is_some() == s.info().uses_chunks)
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
