//! Neighbour search: which particles j lie within the kernel radius of particle i.
//!
//! Both searches visit exactly the particles with `r2 = dx*dx + dy*dy < HSQ` (self included),
//! in increasing index order, so a pass sums their contributions in the same order as the
//! sources' loops: the grid gives the same bits as all-pairs.

mod all_pairs;
mod grid;
pub mod list;

pub use all_pairs::AllPairs;
pub use grid::Grid;
pub use list::{NeighborLists, SLOTS, SlotsMut};

use serde::Serialize;
use sph_strategies::{Executor, KernelPanic};

use crate::sph::state::{Domain, Positions};

/// How candidates are found.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum NeighborMode {
    /// Every particle against every particle, O(N²) per pass: the sources' loops.
    AllPairs,
    /// A uniform cell list with cell size H, rebuilt every step by counting sort: O(N).
    Grid,
}

impl NeighborMode {
    /// Every mode.
    pub const ALL: [NeighborMode; 2] = [NeighborMode::AllPairs, NeighborMode::Grid];

    /// The name used on the command line and in CSV files.
    pub fn as_str(self) -> &'static str {
        match self {
            NeighborMode::AllPairs => "all-pairs",
            NeighborMode::Grid => "grid",
        }
    }
}

impl std::fmt::Display for NeighborMode {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

/// A neighbour search over a set of positions.
pub trait Neighbors: Sync {
    /// Brings the search up to date with `pos` (called once per step, before the passes);
    /// per-particle parts of the work run on `exec`.
    fn rebuild<E: Executor>(&mut self, exec: &E, pos: Positions<'_>) -> Result<(), KernelPanic>;

    /// Calls `visit(j, r2)` for every particle j (including `i` itself) whose squared
    /// distance `r2 = dx*dx + dy*dy` (with `d = x_j − x_i`) is below `hsq`, in increasing j.
    fn for_each_within(
        &self,
        i: usize,
        pos: Positions<'_>,
        hsq: f64,
        visit: impl FnMut(usize, f64),
    );
}

/// Squared distance exactly as the sources compute it: `d = x_j − x_i`, `d.x*d.x + d.y*d.y`.
#[inline(always)]
pub fn distance_squared(xi: f64, yi: f64, xj: f64, yj: f64) -> f64 {
    let dx = xj - xi;
    let dy = yj - yi;
    dx * dx + dy * dy
}

/// Builds the search for `mode` over `domain` with kernel radius `h`.
pub fn build(mode: NeighborMode, domain: Domain, h: f64, n: usize) -> AnyNeighbors {
    match mode {
        NeighborMode::AllPairs => AnyNeighbors::AllPairs(AllPairs),
        NeighborMode::Grid => AnyNeighbors::Grid(Grid::new(domain, h, n)),
    }
}

/// One of the searches, chosen once per run.
#[derive(Debug, Clone)]
pub enum AnyNeighbors {
    /// See [`AllPairs`].
    AllPairs(AllPairs),
    /// See [`Grid`].
    Grid(Grid),
}
