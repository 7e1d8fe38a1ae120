//! Waiting a short, bounded time for a condition without sleeping, for the boards' threads
//! (`erased_job`) before they sleep on a condition variable.
//!
//! Passes follow each other within microseconds, and waking a sleeping thread costs tens of
//! microseconds (more on a virtual machine), so a thread that waits for the next pass, or for
//! the end of one, first watches an atomic hint. How it watches matters when cores are
//! shared: a thread that only spins keeps its core from the very thread it waits for, or from
//! another process, for the whole time. So it spins busily only briefly ([`SPINS`] pause
//! instructions, checking after each), then yields its core between checks (`yield_now`: immediate when the core is free, a real hand-over when
//! another thread wants it), and after [`LIMIT`] gives up, so the caller sleeps.

use std::time::{Duration, Instant};

/// How long a thread watches a hint, spinning then yielding, before it sleeps.
const LIMIT: Duration = Duration::from_micros(200);

/// Pauses spun, checking between them, before the watch yields.
const SPINS: u32 = 127;

/// Returns `true` as soon as `done()` holds, or `false` once [`LIMIT`] has passed without it.
///
/// Busy spinning lasts only [`SPINS`] pauses; after that every check is separated by a
/// `yield_now`, so a thread waiting here never holds a contended core for more than one
/// scheduling decision at a time.
pub(crate) fn spin_then_yield(done: impl Fn() -> bool) -> bool {
    spin_then_yield_for(LIMIT, done)
}

/// [`spin_then_yield`], giving up once `limit` has passed.
pub(crate) fn spin_then_yield_for(limit: Duration, done: impl Fn() -> bool) -> bool {
    // As many pauses as crossbeam's `Backoff` spins (1 + 2 + ... + 64, which this loop
    // replaced), but the condition is checked after every one: `Backoff`'s last run of 64
    // pauses between checks is several microseconds on a CPU with a slow `pause` (about 140
    // cycles on Sapphire Rapids), and a pass's start waited that long to be seen.
    for _ in 0..SPINS {
        if done() {
            return true;
        }
        std::hint::spin_loop();
    }
    let start = Instant::now();
    loop {
        if done() {
            return true;
        }
        if start.elapsed() > limit {
            return false;
        }
        std::thread::yield_now();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

    #[test]
    fn a_condition_that_already_holds_returns_at_once() {
        let checks = AtomicUsize::new(0);
        assert!(spin_then_yield(|| {
            checks.fetch_add(1, Ordering::Relaxed);
            true
        }));
        assert_eq!(checks.into_inner(), 1);
    }

    #[test]
    fn a_condition_that_never_holds_gives_up_so_that_the_caller_can_sleep() {
        assert!(!spin_then_yield(|| false));
    }

    #[test]
    fn a_condition_set_by_another_thread_is_seen() {
        let flag = AtomicBool::new(false);
        std::thread::scope(|s| {
            s.spawn(|| flag.store(true, Ordering::Release));
            // The other thread may not have run within one limit on a loaded machine: retry.
            while !spin_then_yield(|| flag.load(Ordering::Acquire)) {}
        });
    }
}
