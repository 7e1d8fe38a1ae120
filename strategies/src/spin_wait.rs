//! Waiting a short, bounded time for a condition without sleeping, for the boards' threads
//! (`erased_job`) before they sleep on a condition variable.
//!
//! Passes follow each other within microseconds, and waking a sleeping thread costs tens of
//! microseconds (more on a virtual machine), so a thread that waits for the next pass, or for
//! the end of one, first watches an atomic hint. How it watches matters when cores are
//! shared. Two ways, both beginning with [`SPINS`] busy pauses (checking after each) and both
//! giving up after a limit, so that the caller sleeps:
//! - [`spin_then_yield`] then yields its core between checks (`yield_now`: immediate when the
//!   core is free, a hand-over when another thread wants it and the scheduler lets it have
//!   it). A worker waiting for the next pass always watches so: a pass does not wait for a
//!   worker that has not joined it, so a worker that gives its CPU away costs the pass only its
//!   help, and it gives the CPU away between passes, never inside one;
//! - [`spin_unless_beside`] keeps spinning, so that it keeps its CPU, and gives up early once
//!   a thread it waits for turns out to run on the same CPU: the session's thread waiting for
//!   the last workers of a pass, with no more threads than CPUs ([`Watch`]). It holds up the
//!   pass, and a yield to a busy process costs it a whole scheduling slice (see
//!   `whereabouts`).
//!
//! A "team" below is the threads of either board: `team`'s or `crossbeam-pool`'s.

use std::time::{Duration, Instant};

use crate::Placement;
use crate::whereabouts::Whereabouts;

/// How long a thread watches a hint before it sleeps.
pub(crate) const LIMIT: Duration = Duration::from_micros(200);

/// Pauses spun, checking between them, before the watch yields or starts looking at the clock.
const SPINS: u32 = 127;

/// Pauses between two looks at the clock and at who shares the CPU, in [`spin_unless_beside`].
const CHECK_EVERY: u32 = 16;

/// Returns `true` as soon as `done()` holds, or `false` once `limit` has passed without it.
///
/// Busy spinning lasts only [`SPINS`] pauses; after that every check is separated by a
/// `yield_now`, so a thread waiting here never holds a contended core for more than one
/// scheduling decision at a time.
pub(crate) fn spin_then_yield(limit: Duration, done: impl Fn() -> bool) -> bool {
    // As many pauses as crossbeam's `Backoff` spins (1 + 2 + ... + 64, which this loop
    // replaced), but the condition is checked after every one: `Backoff`'s last run of 64
    // pauses between checks is several microseconds on a CPU with a slow `pause` (about 140
    // cycles on Sapphire Rapids), and a pass's start waited that long to be seen.
    if spun(SPINS, &done) {
        return true;
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

/// Returns `true` as soon as `done()` holds, or `false` once `limit` has passed without it or
/// once `beside()` says that a thread being waited for shares the caller's CPU (so that the
/// caller sleeps and leaves the CPU to it). Never yields: on a CPU it does not share with a
/// thread it waits for, the caller keeps its CPU until it sleeps (see `whereabouts`).
pub(crate) fn spin_unless_beside(
    limit: Duration,
    done: impl Fn() -> bool,
    beside: impl Fn() -> bool,
) -> bool {
    if spun(SPINS, &done) {
        return true;
    }
    let start = Instant::now();
    loop {
        if spun(CHECK_EVERY, &done) {
            return true;
        }
        if beside() || start.elapsed() > limit {
            return done();
        }
    }
}

/// Spins up to `pauses` pauses, checking `done()` before each; whether it came to hold.
fn spun(pauses: u32, done: &impl Fn() -> bool) -> bool {
    (0..pauses).any(|_| {
        done() || {
            std::hint::spin_loop();
            false
        }
    })
}

/// How the session's thread watches for the last workers of a pass before it sleeps.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Waiting {
    /// No more threads than CPUs: it spins, keeping its CPU, unless a worker inside the pass
    /// was last seen on the same CPU, and then it sleeps ([`spin_unless_beside`]).
    Spin,
    /// More threads than CPUs, or a system that cannot say which CPU a thread runs on: the
    /// team's threads may share CPUs among themselves, so it yields its CPU between checks, to
    /// whichever of them wants it, before it sleeps ([`spin_then_yield`]).
    Yield,
}

impl Waiting {
    /// How a team of `threads` threads placed as `placement` says waits: more threads than
    /// the CPUs they may use share CPUs among themselves.
    pub(crate) fn for_team(threads: usize, placement: Placement) -> Waiting {
        if threads <= placement.parallelism() && Whereabouts::available() {
            Waiting::Spin
        } else {
            Waiting::Yield
        }
    }
}

/// How a team's session thread watches for the last workers of a pass: its [`Waiting`], and
/// where the workers inside the pass work.
pub(crate) struct Watch {
    waiting: Waiting,
    cpus: Whereabouts,
}

impl Watch {
    /// For a team of `threads` threads (thread 0, the session's, included) that waits as
    /// `waiting` says. A yielding watch never asks where the threads are, so it keeps no
    /// slots, and its threads ask no CPU when they start work.
    pub(crate) fn new(threads: usize, waiting: Waiting) -> Self {
        let slots = match waiting {
            Waiting::Spin => threads,
            Waiting::Yield => 0,
        };
        Watch {
            waiting,
            cpus: Whereabouts::new(slots),
        }
    }

    /// For a team of `threads` threads placed as `placement` says: it waits as
    /// [`Waiting::for_team`] says.
    pub(crate) fn for_team(threads: usize, placement: Placement) -> Self {
        Self::new(threads, Waiting::for_team(threads, placement))
    }

    /// Worker `me` (1 and up) is about to work in a pass: it notes the CPU it runs on.
    pub(crate) fn busy(&self, me: usize) {
        self.cpus.busy(me);
    }

    /// Worker `me` has left the pass.
    pub(crate) fn away(&self, me: usize) {
        self.cpus.away(me);
    }

    /// Watches, on the session's thread, for `done()` (the last workers have left the pass)
    /// before it sleeps; whether it came. A yielding watch lasts `yield_limit`, a spinning one
    /// [`LIMIT`].
    pub(crate) fn last_out(&self, yield_limit: Duration, done: impl Fn() -> bool) -> bool {
        match self.waiting {
            Waiting::Yield => spin_then_yield(yield_limit, done),
            Waiting::Spin => spin_unless_beside(LIMIT, done, || self.cpus.beside_busy(0)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

    #[test]
    fn a_condition_that_already_holds_returns_at_once() {
        let checks = AtomicUsize::new(0);
        assert!(spin_then_yield(LIMIT, || {
            checks.fetch_add(1, Ordering::Relaxed);
            true
        }));
        assert_eq!(checks.into_inner(), 1);
    }

    #[test]
    fn a_condition_that_never_holds_gives_up_so_that_the_caller_can_sleep() {
        assert!(!spin_then_yield(LIMIT, || false));
    }

    #[test]
    fn a_watch_that_keeps_its_cpu_gives_up_early_beside_a_thread_it_waits_for() {
        let long = Duration::from_secs(60);
        assert!(spin_unless_beside(long, || true, || true), "done at once");
        // Beside a busy thread: gives up at its first look, with a last look at the condition.
        let looks = AtomicUsize::new(0);
        let came = spin_unless_beside(
            long,
            || false,
            || {
                looks.fetch_add(1, Ordering::Relaxed);
                true
            },
        );
        assert!(!came && looks.into_inner() == 1, "one look");
        let flag = AtomicBool::new(false);
        let came = spin_unless_beside(
            long,
            || flag.load(Ordering::Relaxed),
            || {
                flag.store(true, Ordering::Relaxed);
                true
            },
        );
        assert!(came, "what holds at the last look counts");
        // Alone on its CPU: gives up once the limit has passed.
        assert!(!spin_unless_beside(
            Duration::from_millis(2),
            || false,
            || false
        ));
    }

    #[test]
    fn the_sessions_watch_gives_up_at_its_first_look_when_a_worker_in_the_pass_shares_its_cpu() {
        if !Whereabouts::available() {
            return; // no CPU to ask: never beside, which the slots' own test checks
        }
        let watch = Watch::new(2, Waiting::Spin);
        let checks = AtomicUsize::new(0);
        let count = || {
            checks.fetch_add(1, Ordering::Relaxed);
            false
        };
        // Worker 1 is this thread, pretending: it runs on the watcher's CPU. The thread may
        // move between the note and the look, so a few tries are allowed. A try that took its
        // whole limit would also end at its first look: it does not count.
        let gave_up_at_once = (0..100).any(|_| {
            checks.store(0, Ordering::Relaxed);
            watch.busy(1);
            let start = Instant::now();
            !watch.last_out(LIMIT, count)
                && start.elapsed() < LIMIT
                && checks.load(Ordering::Relaxed) <= (SPINS + CHECK_EVERY + 1) as usize
        });
        assert!(gave_up_at_once);
        // Worker 1 has left the pass: the watch lasts its limit, looking many times (once the
        // limit has passed it ends at its next look, so a watch descheduled past its limit
        // looks no more than at once beside a worker: a few tries are allowed).
        watch.away(1);
        let watched_on = (0..100).any(|_| {
            checks.store(0, Ordering::Relaxed);
            !watch.last_out(LIMIT, count)
                && checks.load(Ordering::Relaxed) > (SPINS + CHECK_EVERY + 1) as usize
        });
        assert!(watched_on);
    }

    #[test]
    fn a_team_of_more_threads_than_cpus_yields_and_one_of_no_more_spins_where_cpus_are_known() {
        let waiting = |threads, cpus| Waiting::for_team(threads, Placement::new(&|_| {}, cpus));
        let spin = if Whereabouts::available() {
            Waiting::Spin
        } else {
            Waiting::Yield
        };
        assert_eq!(waiting(2, 2), spin);
        assert_eq!(waiting(2, 4), spin);
        assert_eq!(waiting(3, 2), Waiting::Yield);
        assert_eq!(waiting(2, 1), Waiting::Yield);
    }

    #[test]
    fn a_condition_set_by_another_thread_is_seen() {
        let flag = AtomicBool::new(false);
        std::thread::scope(|s| {
            s.spawn(|| flag.store(true, Ordering::Release));
            // The other thread may not have run within one limit on a loaded machine: retry.
            while !spin_then_yield(LIMIT, || flag.load(Ordering::Acquire)) {}
        });
    }
}
