//! Neighbour search: which particles j lie within the kernel radius of particle i.
//!
//! Both searches visit exactly the particles with `r2 = dx*dx + dy*dy < HSQ` (self included),
//! in increasing index order, so a pass sums their contributions in the same order as the
//! sources' loops: the grid gives the same bits as all-pairs. The one exception is the grid in
//! [`SumOrder::Cell`], asked for explicitly, which visits them in the order it finds them.

mod all_pairs;
mod grid;
pub mod list;

pub use all_pairs::AllPairs;
pub use grid::keys::{GridKeys, INDEX_KEYS_MAX_BYTES};
pub use grid::{Grid, GridScratch, InCellOrder, InIndexOrder, PARALLEL_SORT, VisitOrder};
pub use list::{ListKey, ListWriter, NeighborLists, SLOTS, SlotsMut, WCSPH_SLOTS};

use serde::{Deserialize, Serialize};
use sph_strategies::{Executor, KernelPanic};

use crate::simd::Lanes;
use crate::sph::state::{Domain, Positions};

/// The most particles whose grid in [`SumOrder::Cell`] sums Müller's density in eight lanes
/// ([`Neighbors::sums_in_lanes`]); a larger run sums it one hit after another. On this
/// project's Xeon VM (4 December) the lanes took 11 % off the grid's reference run (N = 1000)
/// on AVX-512 and 3 % on the other paths, but added 8–12 % at N = 10⁴ and 10⁵.
pub const CELL_LANES_MAX: usize = 4096;

/// The order a particle's neighbours are visited in, and so the order its sums run in.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum SumOrder {
    /// Increasing index, as the sources' loops: both searches give the seed's and the C++
    /// program's bits. The default.
    #[default]
    Index,
    /// The grid's candidate order: cell rows bottom to top, cells left to right, increasing
    /// index within a cell. No sort per particle, so the grid runs faster, but the sums round
    /// differently: not the sources' bits, though still the same bits on every strategy,
    /// core count, chunk count and SIMD path (the order depends only on the positions).
    /// All-pairs visits candidates in index order, so it has only [`SumOrder::Index`].
    ///
    /// Up to [`CELL_LANES_MAX`] particles, Müller's density sums in eight lanes instead
    /// ([`Neighbors::for_each_eight`]): each
    /// row's candidate k in lane k mod 8, lane sums in candidate order, then the lanes added
    /// in a fixed tree, `((s0 + s4) + (s2 + s6)) + ((s1 + s5) + (s3 + s7))`. AVX-512 takes a
    /// row's eight candidates at once, the other paths one at a time
    /// ([`Neighbors::for_each_in_lanes`]): the same lanes, so the same bits. The force pass
    /// and `wcsph`'s passes sum one neighbour after another in candidate order.
    Cell,
}

impl SumOrder {
    /// Both orders, the default first.
    pub const ALL: [SumOrder; 2] = [SumOrder::Index, SumOrder::Cell];

    /// The name used on the command line and in `--json` output.
    pub fn as_str(self) -> &'static str {
        match self {
            SumOrder::Index => "index",
            SumOrder::Cell => "cell",
        }
    }
}

impl std::fmt::Display for SumOrder {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

/// How candidates are found.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum NeighborMode {
    /// Every particle against every particle, O(N²) per pass: the sources' loops.
    AllPairs,
    /// A uniform cell list with cell size the search radius, rebuilt every step by counting
    /// sort: O(N).
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

/// Positions a search was rebuilt at, as it keeps them ([`Neighbors::rebuilt_at`]):
/// particle `of[k]` was at `(at.x[k], at.y[k])`.
#[derive(Debug, Clone, Copy)]
pub struct Rebuilt<'a> {
    /// The positions, in the search's order.
    pub at: Positions<'a>,
    /// The particle at each place.
    pub of: &'a [u32],
}

/// A neighbour search over a set of positions.
pub trait Neighbors: Sync {
    /// How a neighbour list names a particle this search found: see
    /// [`Neighbors::for_each_listed`].
    type Key: ListKey;

    /// Whether a key is the neighbour's index ([`Neighbors::for_each_listed`] visits the keys
    /// themselves), so that a pass may read a list's slots as indices.
    const KEYS_ARE_INDICES: bool;

    /// Working memory of one [`Neighbors::for_each_within`] call, made once for a run of
    /// particles and handed to each call in turn (its contents between calls mean nothing).
    type Scratch: Default;

    /// Brings the search up to date with `pos` (called once per step, before the passes);
    /// per-particle parts of the work run on `exec`.
    fn rebuild<E: Executor>(&mut self, exec: &E, pos: Positions<'_>) -> Result<(), KernelPanic>;

    /// The positions of the last [`Neighbors::rebuild`], where the search keeps copies of
    /// them: the grid does, in its own order; all-pairs keeps none.
    fn rebuilt_at(&self) -> Option<Rebuilt<'_>> {
        None
    }

    /// Calls `visit(j, r2, key)` for every particle j (including `i` itself) whose squared
    /// distance `r2 = dx*dx + dy*dy` (with `d = x_j − x_i`) is below `hsq`, in the search's
    /// visit order (increasing j, unless a grid in [`SumOrder::Cell`]),
    /// testing candidates in `lanes` where the search uses them (all-pairs does, the grid does
    /// not); every path finds the same j with the same r2 when `pos` holds the positions of
    /// the last [`Neighbors::rebuild`]. The grid finds j by testing i at `pos` against its
    /// copies of the others' positions at the rebuild, among the candidates of i's cell then
    /// (`wcsph`'s kept lists ask it so at positions since, and read only j: the paths' r2 may
    /// then differ, a crowded block's being computed from `pos`).
    ///
    /// `key` names j in a list of i's neighbours ([`Neighbors::for_each_listed`]); it may
    /// exceed [`ListKey::MAX`] (the grid's, among more candidates than a key counts), and such
    /// a list is not used.
    fn for_each_within<L: Lanes>(
        &self,
        scratch: &mut Self::Scratch,
        lanes: L,
        i: usize,
        pos: Positions<'_>,
        hsq: f64,
        visit: impl FnMut(usize, f64, u32),
    );

    /// Whether a pass that can sums its contributions in eight lanes
    /// ([`Neighbors::for_each_eight`], [`Neighbors::for_each_in_lanes`]): the grid in
    /// [`SumOrder::Cell`] over up to [`CELL_LANES_MAX`] particles. Otherwise a pass sums one
    /// hit after another in the visit order of [`Neighbors::for_each_within`]. It depends on
    /// the search and the number of particles alone, so every strategy and path sums alike.
    #[inline(always)]
    fn sums_in_lanes(&self) -> bool {
        false
    }

    /// The lanes of [`Neighbors::for_each_eight`] one candidate at a time, for code that
    /// takes one lane per instruction: calls `visit(lane, j, r2, key)` for every hit of
    /// particle `i` in its lane (0..8), in the order of its lane's sum, with the same r2 and
    /// key, and possibly for candidates that are not hits (`r2 ≥ hsq` or NaN, which a pass
    /// adds as +0 and does not list). The grid visits every candidate of its block, without a
    /// branch; by default, the hits of [`Neighbors::for_each_eight`].
    #[inline(always)]
    fn for_each_in_lanes<L: Lanes>(
        &self,
        scratch: &mut Self::Scratch,
        lanes: L,
        i: usize,
        pos: Positions<'_>,
        hsq: f64,
        mut visit: impl FnMut(usize, usize, f64, u32),
    ) {
        self.for_each_eight(scratch, lanes, i, pos, hsq, |eight| {
            for k in 0..8 {
                if eight.within & (1 << k) != 0 {
                    visit(k, eight.j[k] as usize, eight.r2[k], eight.key[k]);
                }
            }
        });
    }

    /// Calls `visit(eight)` for the candidates of particle `i` (itself included) eight lanes at
    /// a time, every hit of [`Neighbors::for_each_within`] (`r2 < hsq`) in one lane of one call,
    /// its bit set in [`Eight::within`], with the same r2 and key. A pass summing in lanes adds
    /// each call's lanes to eight sums, lane by lane, then the eight sums in a fixed tree
    /// (Müller's density: `passes::density_pressure`). Which lane a hit falls in is the
    /// search's: by default hit h of the visit order is in lane h mod 8 of call h / 8; the
    /// grid's lanes are its candidates' places in their rows.
    #[inline(always)]
    fn for_each_eight<L: Lanes>(
        &self,
        scratch: &mut Self::Scratch,
        lanes: L,
        i: usize,
        pos: Positions<'_>,
        hsq: f64,
        mut visit: impl FnMut(&Eight),
    ) {
        let mut eight = Eight::EMPTY;
        self.for_each_within(scratch, lanes, i, pos, hsq, |j, r2, key| {
            let k = eight.within.count_ones() as usize;
            (eight.r2[k], eight.j[k], eight.key[k]) = (r2, j as u32, key);
            eight.within |= 1 << k;
            if k == 7 {
                visit(&eight);
                eight = Eight::EMPTY;
            }
        });
        if eight.within != 0 {
            visit(&eight);
        }
    }

    /// Calls `visit(j)` for the neighbour each key of `list` names, in order: `list` holds keys
    /// that [`Neighbors::for_each_within`] gave for particle `i` since the last rebuild. (No
    /// search here reads `pos`: the grid's position keys are decoded in i's cell at the
    /// rebuild.)
    fn for_each_listed(
        &self,
        i: usize,
        pos: Positions<'_>,
        list: &[Self::Key],
        visit: impl FnMut(usize),
    );
}

/// A search and the neighbour lists the passes write in its keys.
#[derive(Debug, Clone)]
pub struct Searched<N: Neighbors> {
    /// The search.
    pub search: N,
    /// Every particle's neighbours, in the search's keys.
    pub lists: NeighborLists<N::Key>,
}

impl<N: Neighbors> Searched<N> {
    /// `search` with lists for `listed` particles of `width` slots each.
    fn new(search: N, (listed, width): (usize, usize)) -> Self {
        Searched {
            search,
            lists: NeighborLists::with_slots(listed, width),
        }
    }

    /// New lists of `width` slots for as many particles.
    fn relist(&mut self, width: usize) {
        self.lists = NeighborLists::with_slots(self.lists.len(), width);
    }
}

/// Eight lanes of a particle's candidates ([`Neighbors::for_each_eight`]), `r2` on a 64-byte
/// boundary so that its vector loads and stores never straddle a cache line or a page (see
/// [`Near8`](crate::simd::Near8)).
#[derive(Debug, Clone, Copy)]
#[repr(C, align(64))]
pub struct Eight {
    /// Each lane's squared distance, as [`distance_squared`] computes it; `+∞` in a lane that
    /// holds no candidate, so that `r2 < hsq` is the lane's bit.
    pub r2: [f64; 8],
    /// Each lane's index j.
    pub j: [u32; 8],
    /// Each lane's key (see [`Neighbors::for_each_within`]).
    pub key: [u32; 8],
    /// Bit k: lane k holds a hit, a candidate j with `r2 < hsq` (self included).
    pub within: u8,
}

impl Eight {
    /// No hits.
    const EMPTY: Eight = Eight {
        within: 0,
        r2: [f64::INFINITY; 8],
        j: [0; 8],
        key: [0; 8],
    };
}

/// Squared distance exactly as the sources compute it: `d = x_j − x_i`, `d.x*d.x + d.y*d.y`.
#[inline(always)]
pub fn distance_squared(xi: f64, yi: f64, xj: f64, yj: f64) -> f64 {
    let dx = xj - xi;
    let dy = yj - yi;
    dx * dx + dy * dy
}

/// The rectangle a grid covers (positions outside it fall into its edge cells).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bounds {
    /// Left edge.
    pub min_x: f64,
    /// Lower edge.
    pub min_y: f64,
    /// Right edge.
    pub max_x: f64,
    /// Upper edge.
    pub max_y: f64,
}

impl Bounds {
    /// The domain's walls: [0, width] × [0, height].
    pub fn of(domain: Domain) -> Bounds {
        Bounds {
            min_x: 0.0,
            min_y: 0.0,
            max_x: domain.width,
            max_y: domain.height,
        }
    }

    /// Extent along x.
    pub fn width(&self) -> f64 {
        self.max_x - self.min_x
    }

    /// Extent along y.
    pub fn height(&self) -> f64 {
        self.max_y - self.min_y
    }
}

/// Builds the search for `mode` over `bounds` with search radius `radius` (the cell edge) for
/// `n` particles, with lists of `width` slots for the first `listed` of them: the grid's in the
/// keys [`GridKeys::for_lists`] picks for that size, visiting hits in index order.
pub fn build(
    mode: NeighborMode,
    bounds: Bounds,
    radius: f64,
    n: usize,
    (listed, width): (usize, usize),
) -> AnyNeighbors {
    match mode {
        NeighborMode::AllPairs => AnyNeighbors::AllPairs(Searched::new(AllPairs, (listed, width))),
        NeighborMode::Grid => AnyNeighbors::of_grid(
            Grid::new(bounds, radius, n),
            (listed, width),
            GridKeys::for_lists(listed, width),
            SumOrder::Index,
        ),
    }
}

/// One of the searches, with its lists, chosen once per run; the grid in each of its list keys
/// and visit orders, so that each combination's passes are compiled on their own.
#[derive(Debug, Clone)]
pub enum AnyNeighbors {
    /// See [`AllPairs`].
    AllPairs(Searched<AllPairs>),
    /// See [`Grid`]: position keys, index order.
    GridByPosition(Searched<Grid>),
    /// See [`Grid`]: index keys, index order.
    GridByIndex(Searched<Grid<u32>>),
    /// See [`Grid`]: position keys, cell order.
    GridInCellOrder(Searched<Grid<u8, InCellOrder>>),
    /// See [`Grid`]: index keys, cell order.
    GridByIndexInCellOrder(Searched<Grid<u32, InCellOrder>>),
}

/// A grid taken apart from its lists: the grid, the lists' particles and slots, their keys and
/// the visit order.
type GridParts = (Grid, (usize, usize), GridKeys, SumOrder);

impl AnyNeighbors {
    /// `grid` with new lists of `dims` (particles, slots each) in `keys`, visiting hits in
    /// `order`.
    fn of_grid(grid: Grid, dims: (usize, usize), keys: GridKeys, order: SumOrder) -> AnyNeighbors {
        match (keys, order) {
            (GridKeys::Position, SumOrder::Index) => {
                AnyNeighbors::GridByPosition(Searched::new(grid, dims))
            }
            (GridKeys::Index, SumOrder::Index) => {
                AnyNeighbors::GridByIndex(Searched::new(grid.recast(), dims))
            }
            (GridKeys::Position, SumOrder::Cell) => {
                AnyNeighbors::GridInCellOrder(Searched::new(grid.recast(), dims))
            }
            (GridKeys::Index, SumOrder::Cell) => {
                AnyNeighbors::GridByIndexInCellOrder(Searched::new(grid.recast(), dims))
            }
        }
    }

    /// The same search, the grid rebuilt by `f` from its parts; all-pairs as it is. The old
    /// lists are freed before `f` allocates new ones, so the two never add up in the peak
    /// memory of a large run.
    fn map_grid(self, f: impl FnOnce(GridParts) -> AnyNeighbors) -> AnyNeighbors {
        fn dims<K: ListKey>(lists: NeighborLists<K>) -> (usize, usize) {
            (lists.len(), lists.width())
        }
        match self {
            AnyNeighbors::AllPairs(_) => self,
            AnyNeighbors::GridByPosition(s) => {
                let dims = dims(s.lists);
                f((s.search, dims, GridKeys::Position, SumOrder::Index))
            }
            AnyNeighbors::GridByIndex(s) => {
                let dims = dims(s.lists);
                f((s.search.recast(), dims, GridKeys::Index, SumOrder::Index))
            }
            AnyNeighbors::GridInCellOrder(s) => {
                let dims = dims(s.lists);
                f((s.search.recast(), dims, GridKeys::Position, SumOrder::Cell))
            }
            AnyNeighbors::GridByIndexInCellOrder(s) => {
                let dims = dims(s.lists);
                f((s.search.recast(), dims, GridKeys::Index, SumOrder::Cell))
            }
        }
    }

    /// The same search with lists of `width` slots each (for as many particles).
    pub fn with_list_slots(&mut self, width: usize) {
        match self {
            AnyNeighbors::AllPairs(s) => s.relist(width),
            AnyNeighbors::GridByPosition(s) => s.relist(width),
            AnyNeighbors::GridByIndex(s) => s.relist(width),
            AnyNeighbors::GridInCellOrder(s) => s.relist(width),
            AnyNeighbors::GridByIndexInCellOrder(s) => s.relist(width),
        }
    }

    /// For the grid, the same grid with lists in `keys` (for as many particles, as wide);
    /// all-pairs, which lists indices, as it is. Both keys give the same bits: tests use this
    /// to run either at any size.
    pub fn with_grid_keys(self, keys: GridKeys) -> AnyNeighbors {
        if self.grid_keys() == Some(keys) {
            return self;
        }
        self.map_grid(|(grid, dims, _, order)| AnyNeighbors::of_grid(grid, dims, keys, order))
    }

    /// The same search visiting neighbours in `order`.
    ///
    /// # Errors
    /// All-pairs in [`SumOrder::Cell`]: it has no cells, its candidates come in index order.
    pub fn with_sum_order(self, order: SumOrder) -> Result<AnyNeighbors, CellOrderNeedsGrid> {
        if order == SumOrder::Cell && matches!(self, AnyNeighbors::AllPairs(_)) {
            return Err(CellOrderNeedsGrid);
        }
        if self.sum_order() == order {
            return Ok(self);
        }
        Ok(self.map_grid(|(grid, dims, keys, _)| AnyNeighbors::of_grid(grid, dims, keys, order)))
    }

    /// How the grid's lists name neighbours; `None` for all-pairs.
    pub fn grid_keys(&self) -> Option<GridKeys> {
        match self {
            AnyNeighbors::AllPairs(_) => None,
            AnyNeighbors::GridByPosition(_) | AnyNeighbors::GridInCellOrder(_) => {
                Some(GridKeys::Position)
            }
            AnyNeighbors::GridByIndex(_) | AnyNeighbors::GridByIndexInCellOrder(_) => {
                Some(GridKeys::Index)
            }
        }
    }

    /// The order neighbours are visited in.
    pub fn sum_order(&self) -> SumOrder {
        match self {
            AnyNeighbors::AllPairs(_)
            | AnyNeighbors::GridByPosition(_)
            | AnyNeighbors::GridByIndex(_) => SumOrder::Index,
            AnyNeighbors::GridInCellOrder(_) | AnyNeighbors::GridByIndexInCellOrder(_) => {
                SumOrder::Cell
            }
        }
    }

    /// Bytes held by the search and its lists (capacity).
    pub fn heap_bytes(&self) -> usize {
        match self {
            AnyNeighbors::AllPairs(s) => s.lists.heap_bytes(),
            AnyNeighbors::GridByPosition(s) => s.search.heap_bytes() + s.lists.heap_bytes(),
            AnyNeighbors::GridByIndex(s) => s.search.heap_bytes() + s.lists.heap_bytes(),
            AnyNeighbors::GridInCellOrder(s) => s.search.heap_bytes() + s.lists.heap_bytes(),
            AnyNeighbors::GridByIndexInCellOrder(s) => s.search.heap_bytes() + s.lists.heap_bytes(),
        }
    }
}

/// Cell order asked of all-pairs, which has no cells.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[error("all-pairs has no cells: its sums run in index order")]
pub struct CellOrderNeedsGrid;

#[cfg(test)]
mod tests {
    use super::Eight;
    use std::mem::{align_of, offset_of};

    #[test]
    fn eight_lanes_sit_on_a_64_byte_boundary_as_the_simd_paths_lane_arrays_do() {
        // One vector store of eight f64 lanes then never straddles a cache line or a page.
        assert_eq!(align_of::<Eight>(), 64);
        assert_eq!(offset_of!(Eight, r2) % 64, 0);
    }
}
