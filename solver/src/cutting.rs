//! For tests: an executor that runs every pass in balanced chunks, one after another, cut as a
//! parallel strategy would cut them, and says it has two threads (so that the grid sorts in
//! bands).

use sph_strategies::{Executor, KernelPanic, Split, balanced_chunks};

/// Runs every pass in this many balanced chunks, one after another.
pub(crate) struct Cutting(pub(crate) usize);

impl Executor for Cutting {
    fn for_each_chunk<O, F>(&self, out: O, kernel: F) -> Result<(), KernelPanic>
    where
        O: Split,
        F: Fn(usize, O) + Sync,
    {
        for (first, chunk) in balanced_chunks(out, self.0) {
            kernel(first, chunk);
        }
        Ok(())
    }

    fn threads(&self) -> usize {
        2
    }
}
