//! The grid's stable counting sort of particles by cell: which particles each cell holds, in
//! increasing index.

use sph_strategies::{Executor, KernelPanic};

/// Sorts particles by cell. Holds no state between calls yet; it is the home of the sort's
/// scratch arrays.
#[derive(Debug, Clone, Default)]
pub(super) struct CellSort;

impl CellSort {
    /// Scratch for `n` particles over `cells` cells.
    pub(super) fn new(_n: usize, _cells: usize) -> Self {
        CellSort
    }

    /// Bytes held by the sort's scratch arrays (capacity).
    pub(super) fn heap_bytes(&self) -> usize {
        0
    }

    /// Given each particle's cell (`cell_of[i] < start.len() - 1`), writes `order`, the
    /// particle indices sorted by cell and, within a cell, by index, and `start`, where cell c's
    /// particles are `order[start[c]..start[c + 1]]` (so `start[cells] = n`).
    ///
    /// The result is the one stable order, whichever executor runs it.
    pub(super) fn run<E: Executor>(
        &mut self,
        _exec: &E,
        cell_of: &[u32],
        start: &mut [u32],
        order: &mut [u32],
    ) -> Result<(), KernelPanic> {
        start.fill(0);
        let cells = start.len() - 1;
        for &c in cell_of {
            start[c as usize] += 1;
        }
        // Inclusive prefix sums: start[c] is now where cell c ends.
        let mut sum = 0;
        for s in &mut start[..cells] {
            sum += *s;
            *s = sum;
        }
        start[cells] = sum;
        // Scatter from the last particle down, filling each cell from its end: each cell keeps
        // its particles in increasing index, and start[c] ends up where cell c begins.
        for (i, &c) in cell_of.iter().enumerate().rev() {
            let slot = &mut start[c as usize];
            *slot -= 1;
            order[*slot as usize] = i as u32;
        }
        Ok(())
    }
}
