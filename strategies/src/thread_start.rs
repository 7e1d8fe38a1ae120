//! Starting a strategy's threads: the operating system's refusal is a [`BuildError`], never a
//! panic, and unit tests can make any one start fail.

use std::io;

use crate::BuildError;

/// How a strategy starts its threads. Zero-sized outside this crate's unit tests.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct ThreadStarts {
    /// Test-only fault: the start of the thread with this 0-based index is refused, as if by
    /// the operating system (before anything is spawned).
    #[cfg(test)]
    pub(crate) refuse: Option<usize>,
}

impl ThreadStarts {
    /// Starts thread `index` (0-based) of `count` by calling `spawn`, and turns its refusal
    /// into [`BuildError::ThreadStart`].
    pub(crate) fn start<T>(
        &self,
        index: usize,
        count: usize,
        spawn: impl FnOnce() -> io::Result<T>,
    ) -> Result<T, BuildError> {
        #[cfg(test)]
        if self.refuse == Some(index) {
            return Err(refused(index, count, io::Error::other("refused by a test")));
        }
        spawn().map_err(|source| refused(index, count, source))
    }
}

fn refused(index: usize, count: usize, source: io::Error) -> BuildError {
    BuildError::ThreadStart {
        thread: index + 1,
        threads: count,
        source,
    }
}
