//! A uniform cell list with cell size H (a hair over it), rebuilt every step by a stable
//! counting sort of the particle indices by cell: O(N + cells), deterministic, no hashing of
//! floats.
//!
//! Candidates of particle i are the particles in the 3×3 cells around it. Within one row of
//! the grid the three cells are contiguous in the sorted order, so each row is one slice. The
//! hits are put in index order before they are visited, so sums run in the same order as
//! all-pairs and give the same bits.

use sph_strategies::{Executor, KernelPanic};

mod sort;

use sort::CellSort;

use super::list::written_zeros;
use super::{Bounds, Neighbors, distance_squared};
use crate::simd::Lanes;
use crate::sph::state::Positions;

/// Hits of one particle kept on the stack before spilling to the heap (Müller's presets
/// have about 10, `wcsph` up to about 45 next to a wall).
const INLINE_HITS: usize = 96;

/// The most hits put in order by [`rank_sort`]: its cost grows with the square of the hits,
/// so more (`wcsph` has about 20–45) are sorted by comparison instead. Either gives the one
/// increasing order of distinct indices.
const RANK_SORT_MAX: usize = 24;

/// A cell list over a fixed domain.
#[derive(Debug, Clone)]
pub struct Grid {
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
}

impl Grid {
    /// An empty grid covering `bounds` with cells of edge `h`, with room for `n` particles.
    ///
    /// # Panics
    /// If the grid would need more than `u32::MAX` cells or particles.
    pub fn new(bounds: Bounds, h: f64, n: usize) -> Self {
        // Positions lie in bounds; floor(width / h) is the last column.
        let cols = (bounds.width() / h) as usize + 1;
        let rows = (bounds.height() / h) as usize + 1;
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
            sort: CellSort::new(n, cells),
        }
    }

    /// Bytes held by the grid's arrays (capacity): what `scene::memory::estimate` must
    /// predict (its test compares the two).
    pub fn heap_bytes(&self) -> usize {
        4 * (self.start.capacity() + self.order.capacity() + self.cell_of.capacity())
            + 8 * (self.sorted_x.capacity() + self.sorted_y.capacity())
            + self.sort.heap_bytes()
    }
}

/// Cell size and counts of a grid (small and `Copy`, so kernels can share it).
#[derive(Debug, Clone, Copy)]
struct Shape {
    /// Cells per px: the reciprocal of the cell edge (just over the kernel radius).
    per_cell: f64,
    /// Left edge of the first column.
    x0: f64,
    /// Lower edge of the first row.
    y0: f64,
    /// Cells along x.
    cols: usize,
    /// Cells along y.
    rows: usize,
}

impl Shape {
    /// The (column, row) of a position. Positions outside the domain fall into the edge
    /// cells, which never loses a neighbour: anything within H of an edge-cell particle is in
    /// that cell or the one next to it.
    #[inline]
    fn coords(&self, x: f64, y: f64) -> (usize, usize) {
        // `as i64` saturates (NaN gives 0) and is one instruction on x86-64, unlike `as usize`.
        let cx = (((x - self.x0) * self.per_cell) as i64).clamp(0, self.cols as i64 - 1);
        let cy = (((y - self.y0) * self.per_cell) as i64).clamp(0, self.rows as i64 - 1);
        (cx as usize, cy as usize)
    }

    /// The row-major cell number of a position.
    #[inline]
    fn cell_of(&self, x: f64, y: f64) -> u32 {
        let (cx, cy) = self.coords(x, y);
        (cy * self.cols + cx) as u32
    }
}

impl Neighbors for Grid {
    /// Cell numbers (per particle), the counting sort ([`CellSort`]) and the gather of sorted
    /// positions (per slot) run on the executor.
    fn rebuild<E: Executor>(&mut self, exec: &E, pos: Positions<'_>) -> Result<(), KernelPanic> {
        let n = pos.len();
        let shape = self.shape;
        self.cell_of.resize(n, 0);
        exec.for_each_chunk(&mut self.cell_of[..], |first, cells| {
            for (k, c) in cells.iter_mut().enumerate() {
                *c = shape.cell_of(pos.x[first + k], pos.y[first + k]);
            }
        })?;
        self.order.resize(n, 0);
        self.sort
            .run(exec, &self.cell_of, &mut self.start, &mut self.order)?;
        self.sorted_x.resize(n, 0.0);
        self.sorted_y.resize(n, 0.0);
        let order = &self.order;
        exec.for_each_chunk(
            (&mut self.sorted_x[..], &mut self.sorted_y[..]),
            |first, (xs, ys)| {
                for (k, (sx, sy)) in xs.iter_mut().zip(ys).enumerate() {
                    let j = order[first + k] as usize;
                    (*sx, *sy) = (pos.x[j], pos.y[j]);
                }
            },
        )
    }

    #[inline(always)]
    fn for_each_within<L: Lanes>(
        &self,
        _lanes: L,
        i: usize,
        pos: Positions<'_>,
        hsq: f64,
        mut visit: impl FnMut(usize, f64),
    ) {
        let (xi, yi) = (pos.x[i], pos.y[i]);
        let (cx, cy) = self.shape.coords(xi, yi);
        let (c0, c1) = (cx.saturating_sub(1), (cx + 1).min(self.shape.cols - 1));
        // Hits are collected without branching (every candidate is written, the count only
        // advances on a hit), then put in index order unless they already are, by a
        // branch-free rank sort (a comparison sort past RANK_SORT_MAX hits); a row that would
        // overflow the stack buffer goes to a vector, sorted once. The squared distance is
        // recomputed when a hit is visited (same formula, same bits) so that only indices are
        // moved.
        //
        // The candidates are tested one by one, not in `lanes`: a row holds 3–12 of them, and
        // blocks of eight with a mask measured 8–15 % slower (N = 1000 and 10⁵ in motion).
        let mut hits = [0u32; INLINE_HITS];
        let mut len = 0;
        let mut spilled: Vec<u32> = Vec::new();
        for row in cy.saturating_sub(1)..=(cy + 1).min(self.shape.rows - 1) {
            let lo = self.start[row * self.shape.cols + c0] as usize;
            let hi = self.start[row * self.shape.cols + c1 + 1] as usize;
            let (xs, ys, js) = (
                &self.sorted_x[lo..hi],
                &self.sorted_y[lo..hi],
                &self.order[lo..hi],
            );
            if len + js.len() <= INLINE_HITS {
                for ((&xj, &yj), &j) in xs.iter().zip(ys).zip(js) {
                    hits[len] = j;
                    len += usize::from(distance_squared(xi, yi, xj, yj) < hsq);
                }
            } else {
                spilled.extend(xs.iter().zip(ys).zip(js).filter_map(|((&xj, &yj), &j)| {
                    (distance_squared(xi, yi, xj, yj) < hsq).then_some(j)
                }));
            }
        }
        let mut ranked = [0u32; RANK_SORT_MAX];
        let hits = if spilled.is_empty() && hits[..len].is_sorted() {
            // Rows are scanned bottom to top and cells left to right: where particles are
            // still numbered in that order (a scene's start, a calm region) nothing moves.
            &hits[..len]
        } else if spilled.is_empty() && len <= RANK_SORT_MAX {
            rank_sort(&hits[..len], &mut ranked[..len]);
            &ranked[..len]
        } else if spilled.is_empty() {
            hits[..len].sort_unstable();
            &hits[..len]
        } else {
            spilled.extend_from_slice(&hits[..len]);
            spilled.sort_unstable();
            &spilled[..]
        };
        for &j in hits {
            let j = j as usize;
            visit(j, distance_squared(xi, yi, pos.x[j], pos.y[j]));
        }
    }
}

/// Puts the distinct values of `src` in increasing order into `dst` by counting, for each, how
/// many are smaller: quadratic but branch-free, which beats branching sorts on a few dozen.
#[inline]
fn rank_sort(src: &[u32], dst: &mut [u32]) {
    for &j in src {
        let rank: u32 = src.iter().map(|&w| u32::from(w < j)).sum();
        dst[rank as usize] = j;
    }
}
