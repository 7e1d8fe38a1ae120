//! Where a strategy's worker threads run: what each of them does first, on itself, when it
//! starts (e.g. pin itself to a CPU).
//!
//! This crate does not place threads itself (it knows no CPUs and makes no OS call): a
//! [`Placement`] carries the caller's hook, and every strategy calls it on each worker thread
//! it starts, with the worker's 0-based index, before the worker does anything else. Worker i
//! of a run is:
//! - for the rayon strategies, pool thread i (called once, when the pool starts it);
//! - for `crossbeam-pool`, thread i of the run (0 runs the session);
//! - for `std-static`, the thread of block i of a pass (called on every pass, since each pass
//!   starts its threads: the hook's cost is then part of the strategy's cost per pass);
//! - `seq` starts no thread: it runs on the caller, which the caller places itself.

use std::fmt;

/// The hook a worker thread calls on itself first, with its index.
pub type Hook = dyn Fn(usize) + Sync;

/// What a strategy's worker threads do first. [`Placement::OS`] (the default) does nothing:
/// the operating system places them.
#[derive(Clone, Copy, Default)]
pub struct Placement {
    hook: Option<&'static Hook>,
}

impl Placement {
    /// No hook: the operating system decides where each thread runs.
    pub const OS: Placement = Placement { hook: None };

    /// Every worker thread calls `hook(index)` on itself first.
    pub const fn new(hook: &'static Hook) -> Placement {
        Placement { hook: Some(hook) }
    }

    /// Whether the operating system places the threads (no hook).
    pub fn is_os(&self) -> bool {
        self.hook.is_none()
    }

    /// Runs the hook, if any, for worker `index` (on the worker itself).
    pub fn on_start(&self, index: usize) {
        if let Some(hook) = self.hook {
            hook(index);
        }
    }
}

impl PartialEq for Placement {
    /// The same hook (by address), or both none.
    fn eq(&self, other: &Placement) -> bool {
        match (self.hook, other.hook) {
            (None, None) => true,
            (Some(a), Some(b)) => std::ptr::addr_eq(a, b),
            _ => false,
        }
    }
}

impl Eq for Placement {}

impl fmt::Debug for Placement {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.hook {
            None => f.write_str("Placement::OS"),
            Some(hook) => write!(f, "Placement({:p})", hook as *const Hook as *const ()),
        }
    }
}
