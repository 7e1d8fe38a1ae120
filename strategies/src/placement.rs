//! Where a strategy's worker threads run: what each of them does first, on itself, when it
//! starts (e.g. pin itself to a CPU).
//!
//! This crate does not place threads itself (it asks the OS no more than which CPU a thread
//! runs on, in `whereabouts`): a [`Placement`] carries the caller's hook, and every strategy
//! calls it on each worker thread it starts, with the worker's 0-based index, before the worker
//! does anything else. Worker i of a run is:
//! - for the rayon strategies, pool thread i (called once, when the pool starts it);
//! - for `crossbeam-pool` and `team`, thread i of the run (0 runs the session);
//! - for `chili`, worker 0 is the thread that runs the session (it computes too), and the
//!   pool's threads are workers 1, 2, ... in the order they first take a chunk in the run,
//!   each placed just before that chunk (chili has no thread-start hook);
//! - for `paralight`, the pool thread that took item i of a placement pass run when the
//!   pool is built (each item waits until all have started, so each thread takes one);
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
    /// How many distinct CPUs the hook places workers on (0 without a hook).
    cpus: usize,
}

impl Placement {
    /// No hook: the operating system decides where each thread runs.
    pub const OS: Placement = Placement {
        hook: None,
        cpus: 0,
    };

    /// Every worker thread calls `hook(index)` on itself first, which places it on one of
    /// `cpus` distinct CPUs (at least 1).
    pub const fn new(hook: &'static Hook, cpus: usize) -> Placement {
        Placement {
            hook: Some(hook),
            cpus: if cpus == 0 { 1 } else { cpus },
        }
    }

    /// Whether the operating system places the threads (no hook).
    pub fn is_os(&self) -> bool {
        self.hook.is_none()
    }

    /// How many of a strategy's threads can run at once: the CPUs the hook places them on,
    /// or, without a hook, the CPUs the calling thread may run on. (A pinned caller may run
    /// on one CPU only, so that count would be wrong under a hook.)
    pub fn parallelism(&self) -> usize {
        match self.hook {
            Some(_) => self.cpus,
            None => std::thread::available_parallelism().map_or(1, |n| n.get()),
        }
    }

    /// Runs the hook, if any, for worker `index` (on the worker itself).
    pub fn on_start(&self, index: usize) {
        if let Some(hook) = self.hook {
            hook(index);
        }
    }
}

impl PartialEq for Placement {
    /// The same hook (by address) over as many CPUs, or both none.
    fn eq(&self, other: &Placement) -> bool {
        match (self.hook, other.hook) {
            (None, None) => true,
            (Some(a), Some(b)) => std::ptr::addr_eq(a, b) && self.cpus == other.cpus,
            _ => false,
        }
    }
}

impl Eq for Placement {}

impl fmt::Debug for Placement {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.hook {
            None => f.write_str("Placement::OS"),
            Some(hook) => write!(
                f,
                "Placement({:p}, {} CPUs)",
                hook as *const Hook as *const (), self.cpus
            ),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_hooks_parallelism_is_its_cpus_not_the_callers_mask() {
        static NOTHING: fn(usize) = |_| {};
        let os = std::thread::available_parallelism().map_or(1, |n| n.get());
        assert_eq!(Placement::OS.parallelism(), os);
        // A caller pinned by the hook may run on one CPU, however many the workers get.
        assert_eq!(Placement::new(&NOTHING, os + 3).parallelism(), os + 3);
        assert_eq!(Placement::new(&NOTHING, 0).parallelism(), 1);
        assert_ne!(Placement::new(&NOTHING, 2), Placement::new(&NOTHING, 3));
    }
}
