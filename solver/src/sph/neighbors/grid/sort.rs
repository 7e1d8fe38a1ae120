//! The grid's stable counting sort of particles by cell: which particles each cell holds, in
//! increasing index.
//!
//! A small run sorts on the session's thread ([`CellSort::run`]): a few microseconds. From
//! [`PARALLEL_SORT`] particles on, the sort is most of the serial work of a step (at N = 10⁶,
//! 2.2 ms of a 40 ms step on 2 cores, over the tank's 3 million cells), so it runs on the
//! executor in bands of cells ([`CellSort::run_in_bands`]) when it has more than one thread,
//! fused with the passes around it (their kernel calls then cover blocks of particles and
//! runs of bands, as a trace shows them, not ranges of particles):
//!
//! 1. per block of [`BLOCK`] particles (fixed blocks, whatever the strategy's chunks): each
//!    particle's cell, and how many of the block's particles fall in each of up to [`BANDS`]
//!    bands of consecutive cells (a band is `1 << shift` cells);
//! 2. serially, from those counts: where each block's particles of each band go in a scratch
//!    array ordered by band (blocks in order, so each band's particles stay in increasing
//!    index), and the bands grouped into runs of about equal numbers of particles;
//! 3. per block: each particle's index written to its band's place in the scratch array;
//! 4. per run of bands: the counting sort of its particles by cell (they are in increasing
//!    index already), its cells' starts, and the gather of their positions.
//!
//! Every step's result depends on the particles alone, never on how the executor cut the
//! work, so the order, the starts and the sorted positions are those of the serial sort on
//! every strategy (a test compares them).

use std::sync::atomic::{AtomicU32, Ordering};

use sph_strategies::{Executor, KernelPanic};

use super::shape::Shape;
use crate::sph::state::Positions;

/// From this many particles on, the sort runs in bands on the executor.
pub const PARALLEL_SORT: usize = 1 << 16;

/// Particles per block of steps 1 and 3.
const BLOCK: usize = 1 << 14;

/// The most bands of cells.
const BANDS: usize = 256;

/// Runs of bands that step 4 hands out: enough for dynamic scheduling to even out.
const RUNS: usize = 64;

/// Cells whose starts (zeroed, summed) cost about as much as one particle's sort and gather,
/// for cutting step 4 into runs of equal work: at N = 10⁶ the tank's lowest third of cells
/// holds no particle, and a run of bands cut by particles alone took two and a half times
/// as long as the others.
const CELLS_PER_PARTICLE: usize = 8;

/// A block's particle count in each band, then (after step 2) where its next particle of each
/// band goes.
type BandCounts = [u32; BANDS];

/// Sorts particles by cell, and holds the banded sort's scratch arrays.
#[derive(Debug, Default)]
pub(super) struct CellSort {
    /// Particle indices by band (step 3), empty below [`PARALLEL_SORT`].
    by_band: Vec<AtomicU32>,
    /// One [`BandCounts`] per block.
    counts: Vec<BandCounts>,
}

impl Clone for CellSort {
    /// A fresh scratch of the same size (its contents are rewritten at every sort).
    fn clone(&self) -> Self {
        CellSort::new(self.by_band.len())
    }
}

impl CellSort {
    /// Scratch for `n` particles.
    pub(super) fn new(n: usize) -> Self {
        if n < PARALLEL_SORT {
            return CellSort::default();
        }
        CellSort {
            by_band: (0..n).map(|_| AtomicU32::new(0)).collect(),
            counts: vec![[0; BANDS]; n.div_ceil(BLOCK)],
        }
    }

    /// Bytes the scratch of a sort of `n` particles holds (capacity; made with the grid, used
    /// only with more than one thread).
    pub(super) fn bytes_for(n: usize) -> usize {
        if n < PARALLEL_SORT {
            return 0;
        }
        n.saturating_mul(size_of::<AtomicU32>())
            .saturating_add(n.div_ceil(BLOCK) * size_of::<BandCounts>())
    }

    /// Makes the scratch fit a sort of `n` particles.
    pub(super) fn fit(&mut self, n: usize) {
        if self.by_band.len() != n {
            *self = CellSort::new(n);
        }
    }

    /// Bytes held by the sort's scratch arrays (capacity).
    pub(super) fn heap_bytes(&self) -> usize {
        self.by_band.capacity() * size_of::<AtomicU32>()
            + self.counts.capacity() * size_of::<BandCounts>()
    }

    /// Whether a sort of `n` particles runs in bands on an executor of `threads` threads:
    /// on one thread, the serial sort and passes do less work for the same result.
    pub(super) fn in_bands(n: usize, threads: usize) -> bool {
        n >= PARALLEL_SORT && threads > 1
    }

    /// Given each particle's cell (`cell_of[i] < start.len() - 1`), writes `order`, the
    /// particle indices sorted by cell and, within a cell, by index, and `start`, where cell c's
    /// particles are `order[start[c]..start[c + 1]]` (so `start[cells] = n`). On this thread.
    pub(super) fn run(cell_of: &[u32], start: &mut [u32], order: &mut [u32]) {
        let cells = start.len() - 1;
        let particles = (0..cell_of.len() as u32).zip(cell_of.iter().copied());
        start[cells] = counting_sort(particles, &mut start[..cells], 0, order);
    }

    /// Computes each particle's cell (`cell_of`), the sort of [`CellSort::run`] (`start`,
    /// `order`) and the positions in that order (`sorted`), in bands on `exec`: the same
    /// arrays as the serial passes, on every executor. `cell_of`, `order` and `sorted` have
    /// the positions' length, which the scratch fits ([`CellSort::fit`]).
    pub(super) fn run_in_bands<E: Executor>(
        &mut self,
        exec: &E,
        shape: Shape,
        pos: Positions<'_>,
        arrays: GridArrays<'_>,
    ) -> Result<(), KernelPanic> {
        let GridArrays {
            cell_of,
            start,
            order,
            sorted,
        } = arrays;
        let n = pos.len();
        debug_assert!(self.by_band.len() == n && cell_of.len() == n && order.len() == n);
        let cells = start.len() - 1;
        // The fewest cells per band (a power of two) that makes at most BANDS bands.
        let shift = (cells.div_ceil(BANDS)).next_power_of_two().trailing_zeros();
        let bands = ((cells - 1) >> shift) + 1;

        // 1. Cells, and per block the particles in each band.
        let mut blocks: Vec<_> = cell_of.chunks_mut(BLOCK).zip(&mut self.counts).collect();
        exec.for_each_chunk(&mut blocks[..], |first, blocks| {
            for (b, (cells, counts)) in blocks.iter_mut().enumerate() {
                let at = (first + b) * BLOCK;
                let (xs, ys) = (&pos.x[at..][..cells.len()], &pos.y[at..][..cells.len()]);
                counts.fill(0);
                for ((c, &x), &y) in cells.iter_mut().zip(xs).zip(ys) {
                    *c = shape.cell_of(x, y);
                    counts[(*c >> shift) as usize] += 1;
                }
            }
        })?;
        drop(blocks);

        // 2. Each block's first place in each band, and where each band begins.
        let mut band_start = [0u32; BANDS + 1];
        let mut sum = 0;
        for (band, begins) in band_start[..bands].iter_mut().enumerate() {
            *begins = sum;
            for counts in &mut self.counts {
                (counts[band], sum) = (sum, sum + counts[band]);
            }
        }
        band_start[bands] = sum;

        // 3. Each particle's index to its band's place.
        let (cell_of, by_band) = (&*cell_of, &self.by_band[..]);
        exec.for_each_chunk(&mut self.counts[..], |first, counts| {
            for (b, next) in counts.iter_mut().enumerate() {
                let at = (first + b) * BLOCK;
                for (i, &c) in cell_of[at..(at + BLOCK).min(n)].iter().enumerate() {
                    let slot = &mut next[(c >> shift) as usize];
                    by_band[*slot as usize].store((at + i) as u32, Ordering::Relaxed);
                    *slot += 1;
                }
            }
        })?;

        // 4. Runs of bands of about equal work (particles and cells): sort, starts, gather.
        start[cells] = n as u32;
        let mut runs = Vec::with_capacity(RUNS + 1);
        let (mut order, mut start, mut xs, mut ys) =
            (order, &mut start[..cells], sorted.0, sorted.1);
        let work = n + cells / CELLS_PER_PARTICLE;
        let (mut from, mut done) = (0, 0);
        for band in 0..bands {
            let end = band_start[band + 1] as usize;
            let band_cells = ((band + 1) << shift).min(cells) - (band << shift);
            done += end - band_start[band] as usize + band_cells / CELLS_PER_PARTICLE;
            if band + 1 < bands
                && (done as u64) < (runs.len() as u64 + 1) * work as u64 / RUNS as u64
            {
                continue;
            }
            let (first_cell, last_cell) = (from << shift, ((band + 1) << shift).min(cells));
            let begin = band_start[from] as usize;
            let len = end - begin;
            let (o, rest) = std::mem::take(&mut order).split_at_mut(len);
            let (s, rest_s) = std::mem::take(&mut start).split_at_mut(last_cell - first_cell);
            let (x, rest_x) = std::mem::take(&mut xs).split_at_mut(len);
            let (y, rest_y) = std::mem::take(&mut ys).split_at_mut(len);
            (order, start, xs, ys) = (rest, rest_s, rest_x, rest_y);
            runs.push(BandRun {
                first_cell: first_cell as u32,
                begin: begin as u32,
                order: o,
                start: s,
                sorted: (x, y),
            });
            from = band + 1;
        }
        exec.for_each_chunk(&mut runs[..], |_, runs| {
            for run in runs {
                run.sort(cell_of, by_band, pos);
            }
        })?;
        Ok(())
    }
}

/// The stable counting sort that the serial sort and each run of bands do: `particles` (index
/// and cell, in increasing index; read twice) by cell into `order`, which holds places `base..`
/// of the whole order (cells numbered from the first of `start`). Writes
/// `start[c]`, where cell c's particles begin (`base` plus the particles of the cells before
/// it), and returns where the last cell ends.
#[inline(always)]
fn counting_sort(
    particles: impl DoubleEndedIterator<Item = (u32, u32)> + Clone,
    start: &mut [u32],
    base: u32,
    order: &mut [u32],
) -> u32 {
    start.fill(0);
    for (_, c) in particles.clone() {
        start[c as usize] += 1;
    }
    // Inclusive prefix sums: start[c] is now where cell c ends.
    let mut sum = base;
    for s in start.iter_mut() {
        sum += *s;
        *s = sum;
    }
    // Scatter from the last particle down, filling each cell from its end: each cell keeps its
    // particles in increasing index, and start[c] ends up where cell c begins.
    for (i, c) in particles.rev() {
        let slot = &mut start[c as usize];
        *slot -= 1;
        order[(*slot - base) as usize] = i;
    }
    sum
}

/// The grid's arrays that a sort in bands writes (see [`CellSort::run_in_bands`]).
pub(super) struct GridArrays<'a> {
    /// Each particle's cell.
    pub(super) cell_of: &'a mut [u32],
    /// Where each cell's particles begin in `order`, and `n` after the last cell.
    pub(super) start: &'a mut [u32],
    /// Particle indices sorted by cell.
    pub(super) order: &'a mut [u32],
    /// Positions in `order`: x and y.
    pub(super) sorted: (&'a mut [f64], &'a mut [f64]),
}

/// Step 4's share of the arrays: a run of bands' cells and particles.
struct BandRun<'a> {
    /// Its first cell.
    first_cell: u32,
    /// Its first place in `order` (and in the scratch array).
    begin: u32,
    /// Its places in `order`.
    order: &'a mut [u32],
    /// Its cells' starts.
    start: &'a mut [u32],
    /// Its places in the sorted positions.
    sorted: (&'a mut [f64], &'a mut [f64]),
}

impl BandRun<'_> {
    /// Counting sort of the run's particles (`by_band[begin..][..len]`, in increasing index)
    /// by cell, as [`CellSort::run`] does, then the gather of their positions.
    fn sort(&mut self, cell_of: &[u32], by_band: &[AtomicU32], pos: Positions<'_>) {
        let (first_cell, begin) = (self.first_cell, self.begin);
        let mine = by_band[begin as usize..][..self.order.len()]
            .iter()
            .map(|i| {
                let i = i.load(Ordering::Relaxed);
                (i, cell_of[i as usize] - first_cell)
            });
        counting_sort(mine, self.start, begin, self.order);
        let (xs, ys) = (&mut *self.sorted.0, &mut *self.sorted.1);
        for ((x, y), &j) in xs.iter_mut().zip(ys.iter_mut()).zip(self.order.iter()) {
            (*x, *y) = (pos.x[j as usize], pos.y[j as usize]);
        }
    }
}
