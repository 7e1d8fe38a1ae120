//! The seed paper's published numbers (its Table 1 and Figures 9–10): the Haskell program on
//! an Intel i5-8600K (6 cores at 5 GHz), N = 1000, 1000 steps, all-pairs, `seed` preset.
//!
//! Only the speedups compare with a bench-sph sweep; the absolute times are another program
//! on another machine. The report shows them only beside `seed`/`all-pairs` groups.

use sph_harness::results::key::Group;
use sph_solver::models::Preset;
use sph_solver::sph::neighbors::NeighborMode;

/// The paper's machine, in words.
pub const MACHINE: &str = "Intel i5-8600K, 6 cores at 5 GHz";
/// Particles in the paper's study.
pub const N: usize = 1000;
/// Steps in the paper's study.
pub const STEPS: usize = 1000;
/// The paper's serial time, seconds.
pub const SERIAL_S: f64 = 29.85;

/// One row of the paper's Table 1: the best chunk count at a core count.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PaperRow {
    /// Cores.
    pub cores: usize,
    /// The chunk count with the lowest time (`parListChunk`).
    pub chunks: usize,
    /// Seconds, on the paper's machine.
    pub time_s: f64,
    /// Serial time over this time, as published.
    pub speedup: f64,
}

/// The paper's Table 1.
pub const TABLE: [PaperRow; 5] = [
    PaperRow {
        cores: 2,
        chunks: 45,
        time_s: 14.904,
        speedup: 2.00,
    },
    PaperRow {
        cores: 3,
        chunks: 90,
        time_s: 10.39,
        speedup: 2.87,
    },
    PaperRow {
        cores: 4,
        chunks: 150,
        time_s: 8.106,
        speedup: 3.68,
    },
    PaperRow {
        cores: 5,
        chunks: 175,
        time_s: 6.638,
        speedup: 4.50,
    },
    PaperRow {
        cores: 6,
        chunks: 150,
        time_s: 5.816,
        speedup: 5.13,
    },
];

/// Whether a group is comparable with the paper: the `seed` preset with all-pairs search
/// (N and steps may differ; the report states the paper's).
pub fn comparable(group: &Group) -> bool {
    group.preset == Preset::Seed && group.neighbors == NeighborMode::AllPairs
}

/// The paper's row at `cores`, if it published one.
pub fn at(cores: usize) -> Option<PaperRow> {
    TABLE.iter().copied().find(|r| r.cores == cores)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_published_speedups_follow_from_the_serial_time() {
        for r in TABLE {
            assert!((SERIAL_S / r.time_s - r.speedup).abs() < 0.01, "{r:?}");
        }
        assert_eq!(at(6).map(|r| r.chunks), Some(150));
        assert!(at(1).is_none());
        let group = |preset, neighbors| Group {
            preset,
            neighbors,
            n: 60,
            steps: 3,
        };
        assert!(comparable(&group(Preset::Seed, NeighborMode::AllPairs)));
        assert!(!comparable(&group(Preset::Seed, NeighborMode::Grid)));
        assert!(!comparable(&group(Preset::Cpp, NeighborMode::AllPairs)));
    }
}
