//! A uniform cell list with cell size H (a hair over it), rebuilt every step by a stable
//! counting sort of the particle indices by cell: O(N + cells), deterministic, no hashing of
//! floats.
//!
//! Candidates of particle i are the particles in the 3×3 cells around it (a ring of empty cells
//! around the tank gives every cell all eight neighbours). Within one row of the grid the three
//! cells are contiguous in the sorted order, so each row is one slice. The hits are put in index
//! order before they are visited, so sums run in the same order as all-pairs and give the same
//! bits; in [`SumOrder::Cell`] they are visited in the order found, faster but rounding
//! differently, and Müller's density sums each row's candidate k in lane k mod 8
//! ([`Neighbors::for_each_eight`], [`Neighbors::for_each_in_lanes`]). Collecting and sorting
//! them works in a [`GridScratch`] the caller makes once per run of particles (`hits.rs`). A
//! particle's block is found from the cell the rebuild stored for it, not from its position
//! again: one load instead of converting and clamping two coordinates, which took 9 % off the
//! grid's reference run in cell order on AVX-512 (5 % in index order).
//!
//! A neighbour list names a hit by its index or, in a large run, by its position among the
//! particle's candidates, counted row by row: one byte instead of a four-byte index (Müller's
//! lists take 36 B a particle instead of 132, `wcsph`'s 68 instead of 260), turned back into
//! the index from the particle's own cell when the list is read
//! ([`GridKeys`](keys::GridKeys)).

use std::hint::select_unpredictable;
use std::marker::PhantomData;

use sph_strategies::{Executor, KernelPanic};

mod hits;
pub mod keys;
mod shape;
mod sort;
#[cfg(test)]
mod sort_tests;

pub use hits::GridScratch;
use hits::{
    INLINE_HITS, ONE_LOOP_MAX, RANK_SORT_MAX, SMALL, hit, in_order, index_of, position_of,
    rank_sort, sort_small,
};
use keys::GridKey;
use shape::Shape;
pub use sort::PARALLEL_SORT;
use sort::{CellSort, GridArrays};

use super::list::written_zeros;
use super::{Bounds, Eight, Neighbors, Rebuilt, SumOrder, distance_squared};
use crate::simd::{Lanes, Row8};
use crate::sph::state::Positions;

/// The order a grid visits each particle's hits in, as a type: a run's order is fixed, so each
/// order's passes are compiled without the other's branches.
pub trait VisitOrder: Send + Sync + 'static {
    /// Which order.
    const ORDER: SumOrder;
}

/// Increasing index: the sources' order and bits ([`SumOrder::Index`]).
#[derive(Debug, Clone, Copy, Default)]
pub struct InIndexOrder;

/// The order the candidates are found in ([`SumOrder::Cell`]).
#[derive(Debug, Clone, Copy, Default)]
pub struct InCellOrder;

impl VisitOrder for InIndexOrder {
    const ORDER: SumOrder = SumOrder::Index;
}

impl VisitOrder for InCellOrder {
    const ORDER: SumOrder = SumOrder::Cell;
}

/// A cell list over a fixed domain, listing neighbours in keys of type `K`
/// ([`GridKeys`](keys::GridKeys)) and visiting hits in the order `O`.
#[derive(Debug, Clone)]
pub struct Grid<K = u8, O = InIndexOrder> {
    /// Cell size and counts.
    shape: Shape,
    /// Particles of cell c are `order[start[c]..start[c + 1]]`, in increasing index.
    start: Vec<u32>,
    /// Particle indices sorted by cell (row-major), stable.
    order: Vec<u32>,
    /// Positions in `order`, so that a candidate scan reads contiguous memory.
    sorted_x: Vec<f64>,
    /// See `sorted_x`.
    sorted_y: Vec<f64>,
    /// Each particle's cell, from the last rebuild.
    cell_of: Vec<u32>,
    /// The counting sort's scratch.
    sort: CellSort,
    /// The key type of the lists and the order hits are visited in.
    marker: PhantomData<(K, O)>,
}

impl<K, O> Grid<K, O> {
    /// An empty grid covering `bounds` with cells of edge `h`, with room for `n` particles.
    ///
    /// # Panics
    /// If the grid would need more than `u32::MAX` cells or particles.
    pub fn new(bounds: Bounds, h: f64, n: usize) -> Self {
        // Positions lie in bounds; floor(width / h) is the last column. A ring of empty cells
        // around them gives every cell a full 3×3 block.
        let cols = (bounds.width() / h) as usize + 1 + 2;
        let rows = (bounds.height() / h) as usize + 1 + 2;
        let cells = cols * rows;
        assert!(
            cells < u32::MAX as usize && n < u32::MAX as usize,
            "grid too large"
        );
        Grid {
            shape: Shape {
                // A hair wider than H, so that multiplying by the rounded reciprocal can never
                // put two particles closer than H two cells apart.
                per_cell: 1.0 / (h * (1.0 + 1e-9)),
                x0: bounds.min_x,
                y0: bounds.min_y,
                cols,
                rows,
            },
            start: written_zeros(cells + 1),
            // Written now, so that the first rebuild does not pay for page faults.
            order: written_zeros(n),
            sorted_x: written_zeros(n),
            sorted_y: written_zeros(n),
            cell_of: written_zeros(n),
            sort: CellSort::new(n),
            marker: PhantomData,
        }
    }

    /// The same grid, for lists in keys of type `K2` and visiting hits in the order `O2`.
    pub fn recast<K2, O2>(self) -> Grid<K2, O2> {
        Grid {
            shape: self.shape,
            start: self.start,
            order: self.order,
            sorted_x: self.sorted_x,
            sorted_y: self.sorted_y,
            cell_of: self.cell_of,
            sort: self.sort,
            marker: PhantomData,
        }
    }

    /// Bytes of the scratch a grid for `n` particles makes for its counting sort.
    pub fn sort_scratch_bytes(n: usize) -> usize {
        CellSort::bytes_for(n)
    }

    /// Bytes held by the grid's arrays (capacity): what `scene::memory::estimate` must
    /// predict (its test compares the two).
    pub fn heap_bytes(&self) -> usize {
        4 * (self.start.capacity() + self.order.capacity() + self.cell_of.capacity())
            + 8 * (self.sorted_x.capacity() + self.sorted_y.capacity())
            + self.sort.heap_bytes()
    }
}

/// A list names a neighbour by its index (`u32` keys) or by its position among the particle's
/// candidates (the particles of its 3×3 cells, row by row; `u8` keys: one byte, where a dam
/// break has at most a few dozen candidates).
impl<K: GridKey, O: VisitOrder> Neighbors for Grid<K, O> {
    type Key = K;
    const KEYS_ARE_INDICES: bool = K::BY_INDEX;
    type Scratch = GridScratch;

    /// Cell numbers (per particle) and the gather of sorted positions (per slot) run on the
    /// executor, and so does the counting sort from `sort::PARALLEL_SORT` particles on (in
    /// bands, fused with the other two; see `sort`).
    fn rebuild<E: Executor>(&mut self, exec: &E, pos: Positions<'_>) -> Result<(), KernelPanic> {
        let n = pos.len();
        let shape = self.shape;
        self.cell_of.resize(n, 0);
        self.order.resize(n, 0);
        self.sorted_x.resize(n, 0.0);
        self.sorted_y.resize(n, 0.0);
        if CellSort::in_bands(n, exec.threads()) {
            self.sort.fit(n);
            return self.sort.run_in_bands(
                exec,
                shape,
                pos,
                GridArrays {
                    cell_of: &mut self.cell_of,
                    start: &mut self.start,
                    order: &mut self.order,
                    sorted: (&mut self.sorted_x, &mut self.sorted_y),
                },
            );
        }
        exec.for_each_chunk(&mut self.cell_of[..], |first, cells| {
            let (xs, ys) = (
                &pos.x[first..][..cells.len()],
                &pos.y[first..][..cells.len()],
            );
            for ((c, &x), &y) in cells.iter_mut().zip(xs).zip(ys) {
                *c = shape.cell_of(x, y);
            }
        })?;
        CellSort::run(&self.cell_of, &mut self.start, &mut self.order);
        let order = &self.order;
        // One length for both, so that one bounds check covers both reads.
        let (px, py) = (&pos.x[..n], &pos.y[..n]);
        exec.for_each_chunk(
            (&mut self.sorted_x[..], &mut self.sorted_y[..]),
            |first, (xs, ys)| {
                let order = &order[first..][..xs.len()];
                for ((sx, sy), &j) in xs.iter_mut().zip(ys).zip(order) {
                    (*sx, *sy) = (px[j as usize], py[j as usize]);
                }
            },
        )
    }

    fn rebuilt_at(&self) -> Option<Rebuilt<'_>> {
        let at = Positions {
            x: &self.sorted_x,
            y: &self.sorted_y,
        };
        Some(Rebuilt {
            at,
            of: &self.order,
        })
    }

    #[inline(always)]
    fn for_each_within<L: Lanes>(
        &self,
        scratch: &mut GridScratch,
        lanes: L,
        i: usize,
        pos: Positions<'_>,
        hsq: f64,
        mut visit: impl FnMut(usize, f64, u32),
    ) {
        let (xi, yi) = (pos.x[i], pos.y[i]);
        let block = self.block_of(i);
        let candidates = block.candidates();
        if candidates as usize > INLINE_HITS {
            for h in self.crowded_hits(&block, (xi, yi), hsq) {
                let j = index_of(h);
                // Computed again: the same formula, the same bits.
                let r2 = distance_squared(xi, yi, pos.x[j as usize], pos.y[j as usize]);
                visit(j as usize, r2, key::<K>(j, position_of(h)));
            }
            return;
        }
        // Hits are collected without branching: every candidate written at the next free
        // place, which only a hit keeps, and its squared distance at its position, where its
        // hit finds it again (no position loads when visited; the packed scan in cell order
        // keeps the hits' distances by hit instead). A small block's candidates
        // are scanned in one loop over its three rows (each candidate's place in the sorted
        // order found without a branch), so that the rows' lengths, a few candidates each,
        // are not loop ends to mispredict; a larger block's row by row.
        //
        // Lanes that pack their hits in registers (AVX-512's compress) scan eight candidates
        // of a row at a time instead (`pack_hits`), with the same hits in the same order,
        // where `scans_packed` says so. Without it, blocks of eight with a mask, their hits
        // taken bit by bit, measured 8–15 % slower than one by one.
        let GridScratch {
            hits,
            r2: dists,
            ranked,
        } = scratch;
        let mut len = 0;
        let packs = L::PACKS_HITS && scans_packed(self.order.len(), candidates);
        if packs {
            len = self.pack_hits(&block, lanes, (xi, yi), hsq, hits, dists);
        }
        let mut collect = |t: u32, (xj, yj, j): (f64, f64, u32)| {
            let r2 = distance_squared(xi, yi, xj, yj);
            // len ≤ t < candidates ≤ INLINE_HITS: the wrap never happens, and spares the
            // loop a bounds check.
            hits[len % INLINE_HITS] = hit(j, t);
            dists[t as usize] = r2;
            len += usize::from(r2 < hsq);
        };
        if packs {
            // Collected above.
        } else if candidates <= ONE_LOOP_MAX {
            let slots = block.slots();
            // Cut to one length, so that one bounds check covers all three reads.
            let n = self.order.len();
            let (xs, ys, order) = (&self.sorted_x[..n], &self.sorted_y[..n], &self.order[..n]);
            for t in 0..candidates {
                let s = slots.of(t);
                collect(t, (xs[s], ys[s], order[s]));
            }
        } else {
            self.for_each_by_row(&block, collect);
        }
        // Put in index order unless already so. Rows are scanned bottom to top and cells left
        // to right: where particles are still numbered that way (a scene at rest, a calm
        // region) the hits come in order and nothing moves.
        let hits = if matches!(O::ORDER, SumOrder::Cell) {
            &hits[..len]
        } else if len <= SMALL {
            // The usual case in motion: SMALL places, the rest padding, checked and sorted in
            // a fixed number of steps, so that no loop's end depends on the number of hits.
            hits[len..len + SMALL].fill(u64::MAX);
            let small: &mut [u64; SMALL] = (&mut hits[..SMALL]).try_into().expect("SMALL places");
            if !in_order(small) {
                sort_small(small);
            }
            &hits[..len]
        } else if in_order(&hits[..len]) {
            &hits[..len]
        } else if len <= RANK_SORT_MAX {
            rank_sort(lanes, &hits[..len], &mut ranked[..len]);
            &ranked[..len]
        } else {
            hits[..len].sort_unstable();
            &hits[..len]
        };
        if packs && matches!(O::ORDER, SumOrder::Cell) {
            for (&h, &r2) in hits.iter().zip(&dists[..]) {
                let (j, position) = (index_of(h), position_of(h));
                visit(j as usize, r2, key::<K>(j, position));
            }
            return;
        }
        for &h in hits {
            let (j, position) = (index_of(h), position_of(h));
            // position < candidates ≤ INLINE_HITS: the wrap spares a bounds check.
            let r2 = dists[position as usize % INLINE_HITS];
            visit(j as usize, r2, key::<K>(j, position));
        }
    }

    #[inline(always)]
    fn sums_in_lanes(&self) -> bool {
        matches!(O::ORDER, SumOrder::Cell) && self.order.len() <= super::CELL_LANES_MAX
    }

    /// Each row of the block, bottom to top, eight candidates at a time in the sorted order:
    /// a row's candidate `8g + k` in lane k of the row's g-th call. Every path tests them in
    /// [`Lanes::near8`], so every path puts the same hits in the same lanes.
    #[inline(always)]
    fn for_each_eight<L: Lanes>(
        &self,
        _scratch: &mut GridScratch,
        lanes: L,
        i: usize,
        pos: Positions<'_>,
        hsq: f64,
        mut visit: impl FnMut(&Eight),
    ) {
        let (xi, yi) = (pos.x[i], pos.y[i]);
        let block = self.block_of(i);
        for (&(lo, hi), &base) in block.runs.iter().zip(&block.base) {
            let (lo, hi) = (lo as usize, hi as usize);
            let mut s = lo;
            while s < hi {
                let first = base + (s - lo) as u32;
                self.eight(lanes, (xi, yi), hsq, (s, hi, first), &mut visit);
                s += 8;
            }
        }
    }

    /// Every candidate of the block, hit or not, in the lane [`Grid::for_each_eight`] gives it
    /// (its place in its row, mod 8), without a branch: a small block in one loop over its
    /// rows, as `for_each_within` scans it, a larger one row by row.
    #[inline(always)]
    fn for_each_in_lanes<L: Lanes>(
        &self,
        _scratch: &mut GridScratch,
        _lanes: L,
        i: usize,
        pos: Positions<'_>,
        _hsq: f64,
        mut visit: impl FnMut(usize, usize, f64, u32),
    ) {
        let (xi, yi) = (pos.x[i], pos.y[i]);
        let block = self.block_of(i);
        let n = self.order.len();
        let (xs, ys, order) = (&self.sorted_x[..n], &self.sorted_y[..n], &self.order[..n]);
        let candidates = block.candidates();
        let lane = |t: u32| (block.place_in_row(t) % 8) as usize;
        if candidates <= ONE_LOOP_MAX {
            let slots = block.slots();
            for t in 0..candidates {
                let s = slots.of(t);
                let (xj, yj, j) = (xs[s], ys[s], order[s]);
                let r2 = distance_squared(xi, yi, xj, yj);
                visit(lane(t), j as usize, r2, key::<K>(j, t));
            }
            return;
        }
        self.for_each_by_row(&block, |t, (xj, yj, j)| {
            let r2 = distance_squared(xi, yi, xj, yj);
            visit(lane(t), j as usize, r2, key::<K>(j, t));
        });
    }

    /// An index key is the neighbour. A position key is a hit's position among its block's
    /// candidates, counted along the block's rows: it is one addition and one load away from
    /// the neighbour's index.
    #[inline(always)]
    fn for_each_listed(
        &self,
        i: usize,
        _pos: Positions<'_>,
        list: &[K],
        mut visit: impl FnMut(usize),
    ) {
        if K::BY_INDEX {
            for &key in list {
                visit(key.get() as usize);
            }
            return;
        }
        let slots = self.block_of(i).slots();
        for &key in list {
            visit(self.order[slots.of(key.get())] as usize);
        }
    }
}

/// Whether lanes that pack hits ([`Lanes::PACKS_HITS`]) scan a block of `candidates` (at most
/// [`INLINE_HITS`]) in a grid of `n` particles eight at a time: from 8 particles (one packed
/// scan's read) up to [`PACK_MAX`], and beyond in blocks of [`PACK_CANDIDATES`] or more.
#[inline(always)]
fn scans_packed(n: usize, candidates: u32) -> bool {
    n >= 8 && (n <= PACK_MAX || candidates >= PACK_CANDIDATES)
}

/// The most particles whose grid scans every block (of up to [`INLINE_HITS`] candidates) eight
/// at a time when the lanes pack hits; a larger grid scans a block one by one, unless it holds
/// [`PACK_CANDIDATES`] or more. On the EPYC VM of this project's early sessions the packed scan
/// was 3–12 % faster at N = 1000 and N = 10⁵; on its Xeon VM (3 December, each size run with
/// and without it, interleaved) it was 4–10 % faster at N = 1000 on one core but 3–5 % slower
/// at N = 10⁴–10⁵, and 14–16 % slower on 2 cores at N = 10⁵ and 10⁶ (why is not settled: a
/// row holds three to four candidates at every one of these sizes, and two single-threaded
/// runs side by side did not slow each other). Both scans find the same hits in the same order.
const PACK_MAX: usize = 4096;

/// From this many candidates on, a block of a grid larger than [`PACK_MAX`] is scanned eight at
/// a time all the same: in `wcsph`'s blocks (20–100 candidates) the packed scan measured 5 %
/// faster at R = 60 (about 8,000 particles) on one core and on two. Müller's dam at rest
/// (about 9 candidates a block from N = 10⁴ on) stays below it and keeps the faster one-by-one
/// scan.
const PACK_CANDIDATES: u32 = 16;

/// The eight values of `a` from `at`.
#[inline(always)]
fn eight_at<T>(a: &[T], at: usize) -> &[T; 8] {
    (&a[at..at + 8]).try_into().expect("eight values")
}

/// The eight places of `a` from `at`.
#[inline(always)]
fn eight_of<T>(a: &mut [T], at: usize) -> &mut [T; 8] {
    (&mut a[at..at + 8]).try_into().expect("eight places")
}

/// The key of neighbour `j`, the candidate at `position` in its block, in keys of type `K`.
#[inline(always)]
fn key<K: GridKey>(j: u32, position: u32) -> u32 {
    if K::BY_INDEX { j } else { position }
}

/// The candidates of a particle: the particles of the 3×3 cells around its cell, as three runs
/// of the sorted order, one per row.
#[derive(Debug, Clone, Copy)]
struct Block {
    /// Each row's `order[lo..hi]`, bottom to top.
    runs: [(u32, u32); 3],
    /// Candidates in the rows before each row: the key of a row's first candidate.
    base: [u32; 3],
}

impl<K, O: VisitOrder> Grid<K, O> {
    /// The block of candidates around the position (x, y).
    #[cfg(test)]
    fn block(&self, x: f64, y: f64) -> Block {
        self.block_around(self.shape.cell_of(x, y) as usize)
    }

    /// The block of candidates of particle `i`, from the cell the last rebuild put it in (the
    /// cell of its position then, so the same block as [`Grid::block`] of that position, for
    /// the cost of one load instead of converting and clamping two coordinates).
    #[inline(always)]
    fn block_of(&self, i: usize) -> Block {
        self.block_around(self.cell_of[i] as usize)
    }

    /// The block of candidates around cell `cell` (row-major), which lies inside the ring of
    /// empty cells, so the block never leaves the grid.
    #[inline(always)]
    fn block_around(&self, cell: usize) -> Block {
        let cols = self.shape.cols;
        // The three cells of a row, from the one left of the column of `cell`.
        let run = |middle: usize| {
            let first = middle - 1;
            (self.start[first], self.start[first + 3])
        };
        let runs = [run(cell - cols), run(cell), run(cell + cols)];
        let len = |(lo, hi): (u32, u32)| hi - lo;
        let base1 = len(runs[0]);
        Block {
            runs,
            base: [0, base1, base1 + len(runs[1])],
        }
    }

    /// Collects the hits of `block` around `(xi, yi)` eight candidates at a time (a row's last
    /// eight masked to the row): the hits packed at the front of `hits` in candidate order, as
    /// the one-by-one scan leaves them, and their distances in `dists` (see the stores below).
    /// Returns their number.
    #[inline(always)]
    fn pack_hits<L: Lanes>(
        &self,
        block: &Block,
        lanes: L,
        me: (f64, f64),
        hsq: f64,
        hits: &mut [u64; INLINE_HITS + 8],
        dists: &mut [f64; INLINE_HITS + 8],
    ) -> usize {
        let n = self.order.len();
        let (xs, ys, order) = (&self.sorted_x[..n], &self.sorted_y[..n], &self.order[..n]);
        let mut len = 0;
        for (&(lo, hi), &base) in block.runs.iter().zip(&block.base) {
            let (mut s, hi, mut t) = (lo as usize, hi as usize, base as usize);
            while s < hi {
                // Eight slots from s, or the last eight of the arrays where fewer are left
                // (n ≥ 8): the `skip` lanes before s then belong to earlier candidates.
                let from = s.min(n - 8);
                let skip = s - from;
                let keep = (u8::MAX << skip) & (u8::MAX >> (8 - (hi - from).min(8)));
                let eight = |a: &[f64]| -> [f64; 8] { a[from..from + 8].try_into().expect("8") };
                let row = Row8 {
                    xs: &eight(xs),
                    ys: &eight(ys),
                    order: &order[from..from + 8].try_into().expect("8"),
                    first: (t as u32).wrapping_sub(skip as u32),
                };
                let found = lanes.hits8(me, row, keep, hsq);
                // t < candidates ≤ INLINE_HITS and len ≤ t: both eight places are there.
                // (Stores of eight, not `copy_from_slice` of a varying length: a call.) In cell
                // order the hits are visited as found, so `dists` holds the hits' distances in
                // their order; in index order each candidate's, by position, for after the sort.
                if matches!(O::ORDER, SumOrder::Cell) {
                    *eight_of(dists, len) = found.hit_r2;
                } else if skip == 0 {
                    *eight_of(dists, t) = found.r2;
                } else {
                    for (d, &r2) in dists[t..].iter_mut().zip(&found.r2[skip..]) {
                        *d = r2;
                    }
                }
                *eight_of(hits, len) = found.hits;
                len += found.count;
                s += 8 - skip;
                t += 8 - skip;
            }
        }
        len
    }

    /// Calls `f(position, (x, y, index))` for each of the block's candidates, row by row.
    #[inline(always)]
    fn for_each_by_row(&self, block: &Block, mut f: impl FnMut(u32, (f64, f64, u32))) {
        for (&(lo, hi), &base) in block.runs.iter().zip(&block.base) {
            let (lo, hi) = (lo as usize, hi as usize);
            let row = self.sorted_x[lo..hi]
                .iter()
                .zip(&self.sorted_y[lo..hi])
                .zip(&self.order[lo..hi]);
            for (t, ((&xj, &yj), &j)) in (base..).zip(row) {
                f(t, (xj, yj, j));
            }
        }
    }

    /// The hits of a block of more candidates than [`GridScratch`] holds (a pile): collected
    /// row by row in a vector, in candidate order, then sorted by index unless the grid visits
    /// in cell order.
    ///
    /// It returns them rather than visiting them: a visit closure handed to a call that is not
    /// inlined would make the pass keep its sums in memory, hot loop included.
    #[cold]
    fn crowded_hits(&self, block: &Block, (xi, yi): (f64, f64), hsq: f64) -> Vec<u64>
    where
        O: VisitOrder,
    {
        let mut found = Vec::new();
        self.for_each_by_row(block, |t, (xj, yj, j)| {
            if distance_squared(xi, yi, xj, yj) < hsq {
                found.push(hit(j, t));
            }
        });
        if matches!(O::ORDER, SumOrder::Index) {
            found.sort_unstable();
        }
        found
    }
}

impl<K: GridKey, O> Grid<K, O> {
    /// Calls `visit` with the eight slots from `s` of a row that ends before slot `hi`, whose
    /// slot `s` is the particle's candidate `first` (lanes from `hi` on are empty).
    #[inline(always)]
    fn eight<L: Lanes>(
        &self,
        lanes: L,
        me: (f64, f64),
        hsq: f64,
        (s, hi, first): (usize, usize, u32),
        visit: &mut impl FnMut(&Eight),
    ) {
        let n = self.order.len();
        let (xs, ys, order) = (&self.sorted_x[..n], &self.sorted_y[..n], &self.order[..n]);
        let (bx, by, bj) = if s + 8 <= n {
            (*eight_at(xs, s), *eight_at(ys, s), *eight_at(order, s))
        } else {
            // The last slots of the grid: copied, the lanes past them left empty.
            let tail = |a: &[f64]| std::array::from_fn(|k| a.get(s + k).map_or(0.0, |&v| v));
            let js = std::array::from_fn(|k| order.get(s + k).map_or(0, |&j| j));
            (tail(xs), tail(ys), js)
        };
        let present = ((1u16 << hi.saturating_sub(s).min(8)) - 1) as u8;
        let near = lanes.near8_of(me, &bx, &by, hsq, present);
        let key = if K::BY_INDEX {
            bj
        } else {
            std::array::from_fn(|k| first + k as u32)
        };
        visit(&Eight {
            within: near.mask,
            r2: near.r2,
            j: bj,
            key,
        });
    }
}

impl Block {
    /// The place of the candidate at `position` in its row (0 for a row's first), without a
    /// branch, whichever row it is in.
    #[inline(always)]
    fn place_in_row(&self, position: u32) -> u32 {
        let [_, b1, b2] = self.base;
        let first = select_unpredictable(position >= b1, b1, 0);
        let first = select_unpredictable(position >= b2, b2, first);
        position - first
    }

    /// The block's candidates.
    #[inline(always)]
    fn candidates(&self) -> u32 {
        let (lo, hi) = self.runs[2];
        self.base[2] + (hi - lo)
    }

    /// Where each of the block's candidates lies in the sorted order.
    #[inline(always)]
    fn slots(&self) -> Slots {
        // Where in `order` a position of each row starts: the row's first slot minus the
        // candidates of the rows before it (wrapping: only sums with a position in that row
        // are read).
        let [r0, r1, r2] = self.runs.map(|(lo, _)| lo);
        let [_, b1, b2] = self.base;
        Slots {
            offset: [r0, r1.wrapping_sub(b1), r2.wrapping_sub(b2)],
            rows: [b1, b2],
        }
    }
}

/// Turns a candidate's position in its block (counted row by row) into its slot in the
/// grid's sorted order without a branch, whichever row it is in: the positions of one loop or
/// list come from every row in turn.
#[derive(Debug, Clone, Copy)]
struct Slots {
    /// What each row's positions are offset by.
    offset: [u32; 3],
    /// The first position of the second row and of the third.
    rows: [u32; 2],
}

impl Slots {
    /// The slot of the candidate at `position`.
    #[inline(always)]
    fn of(&self, position: u32) -> usize {
        // Two conditional moves: which row varies from one candidate to the next.
        let [o0, o1, o2] = self.offset;
        let offset = select_unpredictable(position >= self.rows[0], o1, o0);
        let offset = select_unpredictable(position >= self.rows[1], o2, offset);
        position.wrapping_add(offset) as usize
    }
}

#[cfg(test)]
mod tests {
    use sph_strategies::seq::SeqExecutor;

    use super::*;
    use crate::scene::splitmix::SplitMix64;
    use crate::simd::{PackingPortable, Portable, SimdPath};
    use crate::sph::neighbors::AllPairs;

    const H: f64 = 16.0;

    /// Particles in a pile that fills a block past the scratch's places.
    const PILE: usize = INLINE_HITS + 22;

    /// The tests' usual bounds: 20 × 15 cells.
    const BOUNDS: Bounds = Bounds {
        min_x: 0.0,
        min_y: 0.0,
        max_x: 320.0,
        max_y: 240.0,
    };

    fn grid_over<K: GridKey, O: VisitOrder>(x: &[f64], y: &[f64]) -> Grid<K, O> {
        grid_in(BOUNDS, x, y)
    }

    fn grid_in<K: GridKey, O: VisitOrder>(bounds: Bounds, x: &[f64], y: &[f64]) -> Grid<K, O> {
        let mut grid = Grid::<K, O>::new(bounds, H, x.len());
        grid.rebuild(&SeqExecutor, Positions { x, y }).unwrap();
        grid
    }

    /// Every hit of particle i as (j, key), in the order visited.
    fn hits<K: GridKey, O: VisitOrder>(
        grid: &Grid<K, O>,
        i: usize,
        pos: Positions<'_>,
    ) -> Vec<(usize, u32)> {
        let mut found = Vec::new();
        let scratch = &mut GridScratch::default();
        grid.for_each_within(scratch, Portable, i, pos, H * H, |j, _, key| {
            found.push((j, key))
        });
        found
    }

    /// Random positions, some outside the bounds (edge cells), numbered in no spatial order.
    fn scattered(n: usize) -> (Vec<f64>, Vec<f64>) {
        let mut rng = SplitMix64::new(7);
        let mut coord = |extent: f64| rng.next_f64() * (extent + 40.0) - 20.0;
        let x: Vec<f64> = (0..n).map(|_| coord(320.0)).collect();
        let y: Vec<f64> = (0..n).map(|_| coord(240.0)).collect();
        (x, y)
    }

    /// Checks that every particle's hits come in index order and that their keys, listed in
    /// type `K`, name the same neighbours again.
    fn keys_name_their_neighbours_again<K: GridKey>(x: &[f64], y: &[f64]) {
        let pos = Positions { x, y };
        let grid = grid_over::<K, InIndexOrder>(x, y);
        for i in 0..x.len() {
            let found = hits(&grid, i, pos);
            assert!(found.windows(2).all(|w| w[0].0 < w[1].0), "index order");
            let keys: Vec<K> = found
                .iter()
                .map(|&(_, k)| {
                    assert!(k <= K::MAX, "particle {i}: key {k}");
                    K::truncate(k)
                })
                .collect();
            let mut named = Vec::new();
            grid.for_each_listed(i, pos, &keys, |j| named.push(j));
            let js: Vec<usize> = found.iter().map(|&(j, _)| j).collect();
            assert_eq!(named, js, "particle {i}");
        }
    }

    /// Checks every particle's hits (index, r2 bits, order) against a brute-force search, and
    /// counts which scan and sort each took: one loop with the network, row by row, rank sort,
    /// comparison sort, crowded. Returns the counts and how many particles had more than one
    /// hit found already in index order (their positions in the block increase with the index).
    fn check_against_all_pairs(x: &[f64], y: &[f64], paths: &mut [usize; 5]) -> usize {
        let (n, pos) = (x.len(), Positions { x, y });
        let grid = grid_over::<u8, InIndexOrder>(x, y);
        let scratch = &mut GridScratch::default();
        let mut found_in_order = 0;
        for i in 0..n {
            let mut found = Vec::new();
            grid.for_each_within(scratch, Portable, i, pos, H * H, |j, r2, key| {
                found.push((j, r2.to_bits(), key))
            });
            let expected: Vec<(usize, u64)> = (0..n)
                .map(|j| (j, distance_squared(x[i], y[i], x[j], y[j])))
                .filter(|&(_, r2)| r2 < H * H)
                .map(|(j, r2)| (j, r2.to_bits()))
                .collect();
            let got: Vec<(usize, u64)> = found.iter().map(|&(j, r2, _)| (j, r2)).collect();
            assert_eq!(got, expected, "n {n}, particle {i}");
            found_in_order +=
                usize::from(found.len() > 1 && found.windows(2).all(|w| w[0].2 < w[1].2));
            let candidates = grid.block(x[i], y[i]).candidates() as usize;
            let path = match (candidates, found.len()) {
                (c, _) if c > INLINE_HITS => 4,
                (_, hits) if hits > RANK_SORT_MAX => 3,
                (_, hits) if hits > SMALL => 2,
                (c, _) if c > ONE_LOOP_MAX as usize => 1,
                _ => 0,
            };
            paths[path] += 1;
        }
        found_in_order
    }

    #[test]
    fn a_particles_block_from_its_stored_cell_is_the_block_of_its_position() {
        // Positions inside, outside the bounds (edge cells), on a cell edge, far away and NaN.
        let (mut x, mut y) = scattered(2000);
        x.extend([H, 1e300, -1e300, f64::NAN, 5.0]);
        y.extend([2.0 * H, 5.0, f64::NAN, 7.0, f64::INFINITY]);
        let grid = grid_over::<u32, InIndexOrder>(&x, &y);
        for i in 0..x.len() {
            let (stored, again) = (grid.block_of(i), grid.block(x[i], y[i]));
            assert_eq!(
                (stored.runs, stored.base),
                (again.runs, again.base),
                "particle {i} at ({}, {})",
                x[i],
                y[i]
            );
        }
    }

    #[test]
    fn every_scan_and_sort_finds_all_pairs_hits_in_index_order_with_their_distances() {
        // From sparse to crowded: blocks scanned in one loop and row by row, hits put in
        // order by the network, the rank sort and the comparison sort, blocks on the heap.
        let mut paths = [0; 5];
        for n in [150, 600, 1500, 4000, 9000] {
            let (x, y) = scattered(n);
            check_against_all_pairs(&x, &y, &mut paths);
        }
        assert!(paths.iter().all(|&p| p > 10), "{paths:?}");
    }

    #[test]
    fn hits_found_in_index_order_are_visited_as_found_on_every_path() {
        // Particles numbered in the grid's own order (row by row, cell by cell): every block's
        // hits are found in index order, so each path's check finds them in order and no
        // sort runs.
        let mut paths = [0; 5];
        let mut in_order = 0;
        for n in [150, 600, 1500, 4000, 9000] {
            let (x, y) = scattered(n);
            let grid = grid_over::<u32, InIndexOrder>(&x, &y);
            let (x, y): (Vec<f64>, Vec<f64>) = grid
                .order
                .iter()
                .map(|&j| (x[j as usize], y[j as usize]))
                .unzip();
            in_order += check_against_all_pairs(&x, &y, &mut paths);
        }
        assert!(paths.iter().all(|&p| p > 10), "{paths:?}");
        let particles = paths.iter().sum::<usize>();
        assert!(in_order * 10 > particles * 9, "{in_order} of {particles}");
    }

    /// Every hit of particle i as (j, r2 bits, key), in the order visited, on `lanes`, with
    /// working memory reused from particle to particle (as a pass does).
    fn visits<K: GridKey, O: VisitOrder, L: Lanes>(
        grid: &Grid<K, O>,
        i: usize,
        pos: Positions<'_>,
        (lanes, scratch): (L, &mut GridScratch),
    ) -> Vec<(usize, u64, u32)> {
        let mut found = Vec::new();
        lanes.vectorize(
            #[inline(always)]
            || {
                grid.for_each_within(scratch, lanes, i, pos, H * H, |j, r2, key| {
                    found.push((j, r2.to_bits(), key))
                })
            },
        );
        found
    }

    /// Checks that the packed scan (on any machine, with the portable instructions) and every
    /// path visit every particle's hits as the portable path's one-by-one scan does. Returns
    /// how many particles' packed scans read their eight from before a row (the sorted
    /// arrays' last eight slots) and the most candidates a packed block had.
    fn paths_agree<K: GridKey, O: VisitOrder>(x: &[f64], y: &[f64]) -> (usize, u32) {
        paths_agree_in::<K, O>(BOUNDS, x, y)
    }

    /// [`paths_agree`] in a grid over `bounds`.
    fn paths_agree_in<K: GridKey, O: VisitOrder>(
        bounds: Bounds,
        x: &[f64],
        y: &[f64],
    ) -> (usize, u32) {
        let (n, pos) = (x.len(), Positions { x, y });
        let grid = grid_in::<K, O>(bounds, x, y);
        let scratch = &mut GridScratch::default();
        for i in 0..n {
            let want = visits(&grid, i, pos, (Portable, &mut *scratch));
            let packed = visits(&grid, i, pos, (PackingPortable, &mut *scratch));
            assert_eq!(packed, want, "packed, n {n}, particle {i}");
            for path in SimdPath::available() {
                let got = crate::with_lanes!(path.lanes().unwrap(), l => {
                    visits(&grid, i, pos, (l, &mut *scratch))
                });
                assert_eq!(got, want, "{path}, n {n}, particle {i}");
            }
        }
        let blocks = (0..n).map(|i| grid.block(x[i], y[i]));
        let packed = blocks
            .filter(|b| b.candidates() as usize <= INLINE_HITS && scans_packed(n, b.candidates()));
        let from_before = |&(lo, hi): &(u32, u32)| (lo..hi).step_by(8).any(|s| s as usize > n - 8);
        packed.fold((0, 0), |(before, most), b| {
            let before = before + usize::from(b.runs.iter().any(from_before));
            (before, most.max(b.candidates()))
        })
    }

    #[test]
    fn every_path_visits_the_portable_hits_with_their_distances_in_either_order() {
        // From fewer particles than one packed scan reads (not packed) to many, and a pile of
        // 100 in the grid's last cells (the sorted arrays' end) under the scratch's limit.
        let mut sets: Vec<_> = [1, 5, 8, 9, 150, 2000].map(scattered).into();
        let (mut x, mut y) = scattered(300);
        for k in 0..100 {
            x.push(290.0 + (k % 20) as f64 * 1.4);
            y.push(232.0 + (k / 20) as f64 * 1.5);
        }
        sets.push((x, y));
        let (mut from_before, mut most) = (0, 0);
        for (x, y) in &sets {
            let (before, m) = paths_agree::<u8, InIndexOrder>(x, y);
            (from_before, most) = (from_before + before, most.max(m));
            paths_agree::<u8, InCellOrder>(x, y);
            paths_agree::<u32, InCellOrder>(x, y);
        }
        assert!(
            from_before > 10,
            "{from_before} scans read from before their row"
        );
        assert!(most > 100, "the most candidates of a packed block: {most}");
    }

    /// A hit as a test sees it: (j, r2 bits, key).
    type Visit = (usize, u64, u32);

    /// Each call of `for_each_eight` for particle i: its bits and its hits in lane order.
    fn eights<N: Neighbors, L: Lanes>(
        nb: &N,
        i: usize,
        pos: Positions<'_>,
        lanes: L,
    ) -> Vec<(u8, Vec<Visit>)> {
        let mut calls = Vec::new();
        let scratch = &mut N::Scratch::default();
        lanes.vectorize(
            #[inline(always)]
            || {
                nb.for_each_eight(scratch, lanes, i, pos, H * H, |e| {
                    let hits = (0..8).filter(|&k| e.within & (1 << k) != 0);
                    let hits = hits.map(|k| (e.j[k] as usize, e.r2[k].to_bits(), e.key[k]));
                    for k in (0..8).filter(|&k| e.within & (1 << k) == 0) {
                        let r2 = e.r2[k];
                        assert!(
                            r2 >= H * H || r2.is_nan(),
                            "lane {k} without a hit: r2 {r2}"
                        );
                    }
                    calls.push((e.within, hits.collect()));
                })
            },
        );
        calls
    }

    /// Each lane's hits as `for_each_in_lanes` gives them for particle i, in order, with the
    /// non-hits it also visits checked and left out.
    fn in_lanes<N: Neighbors, L: Lanes>(
        nb: &N,
        i: usize,
        pos: Positions<'_>,
        lanes: L,
    ) -> [Vec<Visit>; 8] {
        let mut found: [Vec<Visit>; 8] = Default::default();
        let scratch = &mut N::Scratch::default();
        lanes.vectorize(
            #[inline(always)]
            || {
                nb.for_each_in_lanes(scratch, lanes, i, pos, H * H, |lane, j, r2, key| {
                    if r2 < H * H {
                        found[lane].push((j, r2.to_bits(), key));
                    } else {
                        assert!(r2 >= H * H || r2.is_nan(), "particle {i}: r2 {r2}");
                    }
                })
            },
        );
        found
    }

    /// The hits of `eights` per lane, in call order.
    fn by_lane(calls: &[(u8, Vec<Visit>)]) -> [Vec<Visit>; 8] {
        let mut found: [Vec<Visit>; 8] = Default::default();
        for (bits, hits) in calls {
            let lanes = (0..8).filter(|k| bits & (1 << k) != 0);
            for (k, &hit) in lanes.zip(hits) {
                found[k].push(hit);
            }
        }
        found
    }

    /// Checks that the grid's eights on every path hold the hits `for_each_within` visits in
    /// cell order, in that order, one row's candidates a call in their places, and returns
    /// how many calls had a hit past lane 0 of a row's second eight.
    fn eights_agree<K: GridKey>(bounds: Bounds, x: &[f64], y: &[f64]) -> usize {
        let (n, pos) = (x.len(), Positions { x, y });
        let grid = grid_in::<K, InCellOrder>(bounds, x, y);
        let by_position = grid_in::<u8, InCellOrder>(bounds, x, y);
        let scratch = &mut GridScratch::default();
        let mut later_eights = 0;
        for i in 0..n {
            let want = eights(&grid, i, pos, Portable);
            let flat: Vec<_> = want.iter().flat_map(|(_, hits)| hits.clone()).collect();
            assert_eq!(
                flat,
                visits(&grid, i, pos, (Portable, &mut *scratch)),
                "particle {i}"
            );
            // A hit's lane is its place in its row (its position key less the row's first)
            // modulo 8, and a call holds one eight of one row.
            let block = grid.block(x[i], y[i]);
            for (bits, hits) in eights(&by_position, i, pos, Portable) {
                let lanes = (0..8).filter(|k| bits & (1 << k) != 0);
                let mut places = lanes.zip(&hits).map(|(k, &(_, _, t))| {
                    let row = (0..3).rev().find(|&r| t >= block.base[r]).expect("a row");
                    let place = t - block.base[row];
                    assert_eq!(place % 8, k, "particle {i}: key {t}");
                    (row, place / 8)
                });
                if let Some(first) = places.next() {
                    assert!(
                        places.all(|p| p == first),
                        "particle {i}: one eight of one row"
                    );
                    later_eights += usize::from(first.1 > 0);
                }
            }
            for path in SimdPath::available() {
                let got = crate::with_lanes!(path.lanes().unwrap(), l => eights(&grid, i, pos, l));
                assert_eq!(got, want, "{path}, n {n}, particle {i}");
            }
            // One candidate at a time: the same hits in the same lanes, in the same order.
            let want = by_lane(&want);
            assert_eq!(
                in_lanes(&grid, i, pos, Portable),
                want,
                "n {n}, particle {i}"
            );
            let want = by_lane(&eights(&by_position, i, pos, Portable));
            assert_eq!(
                in_lanes(&by_position, i, pos, Portable),
                want,
                "n {n}, particle {i}"
            );
        }
        later_eights
    }

    #[test]
    fn every_path_gives_the_grids_eights_in_cell_order_a_rows_candidate_k_in_lane_k_mod_8() {
        // Fewer particles than eight (every read from the arrays' tail), sparse to crowded,
        // and a pile past the scratch's limit in the grid's last cells.
        let mut sets: Vec<_> = [1, 5, 9, 150, 2000].map(scattered).into();
        let (mut x, mut y) = scattered(300);
        for k in 0..INLINE_HITS + 30 {
            x.push(290.0 + (k % 20) as f64 * 0.7);
            y.push(232.0 + (k / 20) as f64 * 0.8);
        }
        sets.push((x, y));
        let mut later_eights = 0;
        for (x, y) in &sets {
            later_eights += eights_agree::<u8>(BOUNDS, x, y);
            later_eights += eights_agree::<u32>(BOUNDS, x, y);
        }
        assert!(
            later_eights > 100,
            "{later_eights} hits past a row's first eight"
        );
    }

    #[test]
    fn mueller_density_in_lanes_has_the_same_bits_one_candidate_or_eight_at_a_time() {
        use crate::models::Preset;
        use crate::models::mueller::passes::density_pressure;
        use crate::sph::neighbors::NeighborLists;

        // Sparse to crowded, with a pile past the scratch's limit: the eights' path (packing
        // lanes, on any machine) and the one-at-a-time path (portable) give the same density
        // and list for every particle.
        let prm = Preset::Seed.params();
        let (mut x, mut y) = scattered(3000);
        for k in 0..INLINE_HITS + 30 {
            x.push(290.0 + (k % 20) as f64 * 0.7);
            y.push(232.0 + (k / 20) as f64 * 0.8);
        }
        let pos = Positions { x: &x, y: &y };
        let grid = grid_over::<u32, InCellOrder>(&x, &y);
        let density = |i: usize, packing: bool| {
            let mut lists = NeighborLists::<u32>::with_slots(1, 32);
            let (counts, mut slots) = lists.split_mut();
            let (scratch, list) = (&mut GridScratch::default(), slots.particle(0));
            let (rho, p, count) = if packing {
                density_pressure(i, scratch, PackingPortable, pos, &grid, &prm, list)
            } else {
                density_pressure(i, scratch, Portable, pos, &grid, &prm, list)
            };
            counts[0] = count;
            let listed = lists.of(0).map(<[u32]>::to_vec);
            (rho.to_bits(), p.to_bits(), count, listed)
        };
        let mut crowded = 0;
        for i in 0..x.len() {
            let (one, eight) = (density(i, false), density(i, true));
            assert_eq!(one, eight, "particle {i}");
            crowded += usize::from(one.2 > 8);
        }
        assert!(
            crowded > 100,
            "{crowded} particles with more than 8 neighbours"
        );
    }

    #[test]
    fn only_a_grid_in_cell_order_of_up_to_cell_lanes_max_particles_sums_in_lanes() {
        use crate::sph::neighbors::CELL_LANES_MAX;

        for n in [1, CELL_LANES_MAX, CELL_LANES_MAX + 1] {
            let (x, y) = scattered(n);
            let small = n <= CELL_LANES_MAX;
            assert_eq!(grid_over::<u8, InCellOrder>(&x, &y).sums_in_lanes(), small);
            assert_eq!(grid_over::<u32, InCellOrder>(&x, &y).sums_in_lanes(), small);
            assert!(!grid_over::<u32, InIndexOrder>(&x, &y).sums_in_lanes());
        }
        assert!(!AllPairs.sums_in_lanes());
    }

    #[test]
    fn all_pairs_eights_hold_its_hits_in_index_order_eight_a_call() {
        let (x, y) = scattered(600);
        let pos = Positions { x: &x, y: &y };
        for i in 0..x.len() {
            let calls = eights(&AllPairs, i, pos, Portable);
            let mut want = Vec::new();
            AllPairs.for_each_within(&mut (), Portable, i, pos, H * H, |j, r2, key| {
                want.push((j, r2.to_bits(), key))
            });
            let flat: Vec<_> = calls.iter().flat_map(|(_, hits)| hits.clone()).collect();
            assert_eq!(flat, want, "particle {i}");
            assert_eq!(in_lanes(&AllPairs, i, pos, Portable), by_lane(&calls));
            let full = calls.len().saturating_sub(1);
            assert!(calls[..full].iter().all(|(bits, _)| *bits == u8::MAX));
            assert!(
                calls
                    .iter()
                    .all(|(bits, _)| bits.wrapping_add(1) & bits == 0),
                "lanes from 0"
            );
        }
    }

    #[test]
    fn a_grid_over_pack_max_packs_its_crowded_blocks_and_scans_the_others_one_by_one() {
        // One particle a cell, jittered, over more particles than PACK_MAX (blocks of about 9
        // candidates: one by one), and a pile whose blocks hold PACK_CANDIDATES or more
        // (packed), numbered in no spatial order.
        let (cols, rows) = (80, 60);
        let bounds = Bounds {
            min_x: 0.0,
            min_y: 0.0,
            max_x: cols as f64 * H,
            max_y: rows as f64 * H,
        };
        let mut rng = SplitMix64::new(11);
        let mut points: Vec<(f64, f64)> = (0..cols * rows)
            .map(|k| {
                let (c, r) = ((k % cols) as f64, (k / cols) as f64);
                let mut jitter = || 0.1 + 0.8 * rng.next_f64();
                ((c + jitter()) * H, (r + jitter()) * H)
            })
            .collect();
        points
            .extend((0..30).map(|k| (400.0 + (k % 6) as f64 * 2.5, 300.0 + (k / 6) as f64 * 2.5)));
        for k in (1..points.len()).rev() {
            points.swap(k, (rng.next_f64() * (k + 1) as f64) as usize);
        }
        let (x, y): (Vec<f64>, Vec<f64>) = points.into_iter().unzip();
        let grid = grid_in::<u8, InIndexOrder>(bounds, &x, &y);
        let packed = (0..x.len())
            .filter(|&i| scans_packed(x.len(), grid.block(x[i], y[i]).candidates()))
            .count();
        assert!(x.len() > PACK_MAX);
        assert!(
            packed > 0 && packed < x.len() / 10,
            "{packed} packed blocks"
        );
        paths_agree_in::<u8, InIndexOrder>(bounds, &x, &y);
        paths_agree_in::<u8, InCellOrder>(bounds, &x, &y);
        paths_agree_in::<u32, InCellOrder>(bounds, &x, &y);
    }

    #[test]
    fn every_position_key_names_its_neighbour_again() {
        let (x, y) = scattered(2000);
        keys_name_their_neighbours_again::<u8>(&x, &y);
    }

    #[test]
    fn index_keys_are_the_neighbours_and_find_what_position_keys_find() {
        let (x, y) = scattered(2000);
        keys_name_their_neighbours_again::<u32>(&x, &y);
        let pos = Positions { x: &x, y: &y };
        let by_index = grid_over::<u32, InIndexOrder>(&x, &y);
        let by_position = grid_over::<u8, InIndexOrder>(&x, &y);
        let js = |found: Vec<(usize, u32)>| found.into_iter().map(|(j, _)| j).collect::<Vec<_>>();
        for i in 0..x.len() {
            let found = hits(&by_index, i, pos);
            assert!(
                found.iter().all(|&(j, key)| key as usize == j),
                "particle {i}"
            );
            assert_eq!(js(found), js(hits(&by_position, i, pos)), "particle {i}");
        }
    }

    #[test]
    fn cell_order_visits_hits_in_candidate_order_with_either_key_crowded_blocks_too() {
        let (mut x, mut y) = scattered(2000);
        // And a pile in one cell row (more than INLINE_HITS, so a block holding it is collected
        // on the heap) with particles just above it that reach into it.
        for k in 0..PILE {
            x.push(81.0 + (k % 40) as f64 * 1.1);
            y.push(81.0 + (k / 40) as f64 * 0.5);
        }
        x.extend([100.0, 103.0, 98.0, 95.0]);
        y.extend([96.5, 99.0, 104.0, 97.0]);
        let pos = Positions { x: &x, y: &y };
        let by_index = grid_over::<u8, InIndexOrder>(&x, &y);
        let by_cell = grid_over::<u8, InCellOrder>(&x, &y);
        let by_cell_with_index_keys = grid_over::<u32, InCellOrder>(&x, &y);
        let mut crowded_hits = 0;
        for i in 0..x.len() {
            let found = hits(&by_cell, i, pos);
            assert!(found.windows(2).all(|w| w[0].1 < w[1].1), "particle {i}");
            let mut js: Vec<usize> = found.iter().map(|&(j, _)| j).collect();
            let keys: Vec<u8> = found.iter().map(|&(_, k)| k as u8).collect();
            let mut named = Vec::new();
            by_cell.for_each_listed(i, pos, &keys, |j| named.push(j));
            assert_eq!(
                named, js,
                "particle {i}: keys name the hits in the order visited"
            );
            let with_index_keys = hits(&by_cell_with_index_keys, i, pos);
            assert!(with_index_keys.iter().all(|&(j, key)| key as usize == j));
            let js_with_index_keys: Vec<usize> = with_index_keys.iter().map(|h| h.0).collect();
            assert_eq!(
                js_with_index_keys, js,
                "particle {i}: either key, one order"
            );
            js.sort_unstable();
            let in_index_order: Vec<usize> = hits(&by_index, i, pos).iter().map(|h| h.0).collect();
            assert_eq!(js, in_index_order, "particle {i}");
            let pile = 2000..2000 + PILE;
            crowded_hits +=
                usize::from(i >= pile.end && found.iter().any(|&(j, _)| pile.contains(&j)));
        }
        assert!(
            crowded_hits >= 2,
            "the pile's row is reached from the row above"
        );
    }

    #[test]
    fn keys_from_a_block_too_large_for_the_scratch_name_their_neighbours_again() {
        // A pile in the row below particle PILE's (more than INLINE_HITS), out of its reach,
        // plus a few in reach on both sides: the block is collected on the heap.
        let (mut x, mut y): (Vec<f64>, Vec<f64>) = (0..PILE)
            .map(|k| (81.0 + (k % 40) as f64 * 1.1, 81.0 + (k / 40) as f64 * 0.5))
            .unzip();
        x.extend([101.0, 103.0, 100.0, 104.0]);
        y.extend([105.0, 106.0, 112.0, 95.0]);
        let pos = Positions { x: &x, y: &y };
        let grid = grid_over::<u8, InIndexOrder>(&x, &y);
        let found = hits(&grid, PILE, pos);
        let js: Vec<usize> = found.iter().map(|&(j, _)| j).collect();
        assert_eq!(js, [PILE, PILE + 1, PILE + 2, PILE + 3]);
        let keys: Vec<u8> = found
            .iter()
            .map(|&(_, k)| u8::try_from(k).unwrap())
            .collect();
        let mut named = Vec::new();
        grid.for_each_listed(PILE, pos, &keys, |j| named.push(j));
        assert_eq!(named, js);
    }

    #[test]
    fn a_block_of_more_candidates_than_a_key_counts_gives_keys_past_u8() {
        // A pile of 300 in the row below particle 300's, out of its reach, comes first among
        // its candidates, so its own neighbours' keys start at 300.
        let (mut x, mut y): (Vec<f64>, Vec<f64>) = (0..300)
            .map(|k| (100.0 + (k % 20) as f64 * 0.2, 81.0 + (k / 20) as f64 * 0.2))
            .unzip();
        x.extend([101.0, 103.0, 105.0]);
        y.extend([105.0, 106.0, 107.0]);
        let pos = Positions { x: &x, y: &y };
        let grid = grid_over::<u8, InIndexOrder>(&x, &y);
        let found = hits(&grid, 300, pos);
        let js: Vec<usize> = found.iter().map(|&(j, _)| j).collect();
        assert_eq!(js, [300, 301, 302]);
        assert!(found.iter().all(|&(_, key)| key >= 300), "{found:?}");
    }
}
