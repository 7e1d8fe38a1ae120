//! The key of a cell, shared by the sweep's plan, the rows of the results files, `--resume` and
//! the report.
//!
//! A **group** is one (preset, neighbours, N, steps): the same initial state and the same
//! final checksum for every strategy; its reference is `seq` at 1 core. A **cell** is one
//! strategy at one cores value (and one chunks value, for strategies that use chunks) in a
//! group: the unit the sweep measures and the key of its rows.

use sph_strategies::{Config, StrategyName};

use crate::topology::Pin;

use sph_solver::models::Preset;
use sph_solver::sph::neighbors::NeighborMode;

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
            crate::output::console::plural(self.steps, "step", "steps")
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
    /// Where its threads run (`--pin`; [`Pin::None`], the operating system, for `seq`).
    pub pin: Pin,
}

impl Cell {
    /// The group's reference cell: `seq`, at the one core (and no chunks) the registry says
    /// it uses. It is measured once per group: the denominator of the group's speedups and
    /// the source of its reference checksum.
    pub fn reference(group: Group) -> Cell {
        let info = StrategyName::Seq.info();
        Cell {
            group,
            strategy: StrategyName::Seq,
            cores: info.effective_cores(1),
            chunks: info.effective_chunks(1),
            pin: Pin::None,
        }
    }

    /// Whether this is its group's `seq` reference cell.
    pub fn is_reference(&self) -> bool {
        self.strategy == StrategyName::Seq
    }

    /// The strategy configuration (strategies without chunks ignore `chunks`), its threads
    /// placed by the operating system: the runner places them as `pin` says.
    pub fn config(&self) -> Config {
        Config::new(self.cores, self.chunks.unwrap_or(1))
    }

    /// Particles in the largest of the `min(chunks, n)` balanced chunks:
    /// `ceil(n / min(chunks, n))`.
    pub fn particles_per_chunk(&self) -> Option<usize> {
        let n = self.group.n;
        self.chunks.map(|k| n.div_ceil(k.min(n)))
    }

    /// Whether the cell asks for more threads than the machine has.
    pub fn oversubscribed(&self, hardware_threads: usize) -> bool {
        self.cores > hardware_threads
    }

    /// The text that seeds the cell's bootstrap streams (the sweep's `bootstrap::rng_for`),
    /// frozen so that a display change never changes a results file (`rayon-chunks, 2 cores,
    /// 10 chunks`, `seq, 1 core`, `std-static, 4 cores, pin spread`; unpinned cells keep the
    /// text they had before `--pin` existed).
    pub fn stream_key(&self) -> String {
        let cores = if self.cores == 1 { "core" } else { "cores" };
        let unpinned = match self.chunks {
            Some(k) => format!("{}, {} {cores}, {k} chunks", self.strategy, self.cores),
            None => format!("{}, {} {cores}", self.strategy, self.cores),
        };
        match self.pin {
            Pin::None => unpinned,
            pin => format!("{unpinned}, pin {pin}"),
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

/// A seed-preset group of `neighbors` with 60 particles and 3 steps: the tests' small cell.
#[cfg(any(test, feature = "testing"))]
pub fn test_group(neighbors: sph_solver::sph::neighbors::NeighborMode) -> Group {
    Group {
        preset: sph_solver::models::Preset::Seed,
        neighbors,
        n: 60,
        steps: 3,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_group_label_has_the_sweep_wording_and_the_report_wording() {
        let g = Group {
            preset: Preset::Seed,
            neighbors: NeighborMode::AllPairs,
            n: 1000,
            steps: 1,
        };
        assert_eq!(
            g.label(LabelStyle::Sweep),
            "preset seed, all-pairs, N = 1000, 1 step"
        );
        assert_eq!(
            g.label(LabelStyle::Report),
            "seed preset, all-pairs, N = 1000, 1 step"
        );
        assert_eq!(g.slug(), "seed-all-pairs-n1000-s1");
        let cell = Cell {
            group: g,
            strategy: StrategyName::RayonChunks,
            cores: 2,
            chunks: Some(10),
            pin: Pin::None,
        };
        assert_eq!(
            cell.label_with_group(),
            "rayon-chunks, 2 cores, 10 chunks (preset seed, all-pairs, N = 1000, 1 step)"
        );
        assert!(!cell.is_reference());
        let spread = Cell {
            pin: Pin::Spread,
            ..cell
        };
        assert_eq!(
            spread.label(),
            "rayon-chunks, 2 cores, 10 chunks, pin spread"
        );
    }
}
