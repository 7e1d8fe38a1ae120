//! [`TeamBoard`]: the books of a pass in one atomic word, for `team`'s threads.
//!
//! The word holds the pass's epoch (high 32 bits), whether it is open (bit 31), and how many
//! workers are inside its job (low 31 bits). The dispatcher opens a pass with one store, a
//! worker joins it with a compare-and-swap that succeeds only while the pass is open, and
//! leaves it with a subtraction; the dispatcher closes it with an `and`, after which no
//! compare-and-swap can succeed, and waits until the count is zero. The pass's job sits on the
//! word's cache line, so a worker that sees the pass open has its job too. Besides, each
//! worker notes in a slot of its own the CPU it works on in a pass (`whereabouts`), for the
//! dispatcher's watch before it sleeps (`spin_wait::Watch`). Everything else — sleeping after
//! that watch, waking sleepers, keeping the first panic — happens only when somebody sleeps or
//! something panicked.

use std::cell::UnsafeCell;
use std::mem;
use std::sync::atomic::{AtomicBool, AtomicU64, AtomicUsize, Ordering};
use std::sync::{Condvar, Mutex, MutexGuard, PoisonError};
use std::time::Duration;

use crossbeam::utils::CachePadded;

use super::{AbortOnUnwind, ErasedJob};
use crate::spin_wait::{self, Watch};
use crate::{KernelPanic, panic};

/// The pass is open: workers may join it.
const OPEN: u64 = 1 << 31;
/// The workers inside the pass's job.
const INSIDE: u64 = OPEN - 1;
/// One epoch.
const EPOCH: u64 = 1 << 32;

/// How long the dispatcher of a team that yields (`Waiting::Yield`) watches for the last worker
/// of a closed pass before it sleeps. Short: by then every chunk has been taken, so a worker
/// still inside is either busy with its last chunk or descheduled in it, perhaps on the
/// dispatcher's own CPU.
const LAST_OUT: Duration = Duration::from_micros(20);

/// What a worker reads to join a pass.
struct PassLine {
    /// Epoch, open, inside (see the module's docs).
    word: AtomicU64,
    /// The last pass's job (before the first, a no-op that is never called). Written by the
    /// dispatcher only between passes — after the last worker of the previous pass counted
    /// itself out, before the opening store — and read by a worker only inside a pass it
    /// joined, so a read and a write never overlap (see `run` and `serve`).
    job: UnsafeCell<ErasedJob>,
}

// SAFETY: `word` is atomic; `job` is written and read only as its docs say, so every read of
// it happens after the write it reads and before the next one.
unsafe impl Sync for PassLine {}

fn epoch(word: u64) -> u64 {
    word >> 32
}

/// A rendezvous between one dispatching thread and the worker threads that serve the board,
/// with [`JobBoard`](super::JobBoard)'s promise — a pass waits only for the workers that
/// joined it, so a job must help until done — at a lower cost per pass (see the module's
/// docs). Each serving thread has an index, which it passes to the job; the dispatcher's is 0.
pub(crate) struct TeamBoard {
    /// The pass word and its job, on a cache line of their own: the workers watch it, and
    /// one transfer of the line brings a worker both.
    pass: CachePadded<PassLine>,
    /// A `run` is between opening its pass and returning.
    in_flight: AtomicBool,
    shutdown: AtomicBool,
    /// The first panic that escaped a worker's call of the pass's job, and whether there is
    /// one (so that a pass without a panic takes no lock).
    escaped: Mutex<Option<KernelPanic>>,
    panicked: AtomicBool,
    /// Workers asleep on `to_workers`, and whether the dispatcher sleeps on `to_dispatcher`:
    /// a notification (a system call) is sent only when someone sleeps.
    workers_asleep: AtomicUsize,
    dispatcher_asleep: AtomicBool,
    /// Held by a thread between its last look at `pass` and its sleep, and by a waker
    /// before it notifies, so that no wake-up is lost.
    sleep: Mutex<()>,
    to_workers: Condvar,
    to_dispatcher: Condvar,
    /// How the dispatcher watches for the last workers of a pass, and where the workers inside
    /// a pass run.
    watch: Watch,
}

impl TeamBoard {
    /// A board with no pass yet, whose dispatcher watches as `watch` says.
    pub(crate) fn new(watch: Watch) -> Self {
        TeamBoard {
            pass: CachePadded::new(PassLine {
                word: AtomicU64::new(0),
                job: UnsafeCell::new(ErasedJob::new(&|_| {})),
            }),
            in_flight: AtomicBool::new(false),
            shutdown: AtomicBool::new(false),
            escaped: Mutex::new(None),
            panicked: AtomicBool::new(false),
            workers_asleep: AtomicUsize::new(0),
            dispatcher_asleep: AtomicBool::new(false),
            sleep: Mutex::new(()),
            to_workers: Condvar::new(),
            to_dispatcher: Condvar::new(),
            watch,
        }
    }

    /// Runs `job(0)` on the calling thread and `job(index)` on every worker that joins while
    /// the pass is open (each at most once), and returns when all of those calls have
    /// finished. The pass closes when the calling thread's own call returns; `job` must help
    /// until done. A panic that escapes `job` is caught and returned (the caller's own first,
    /// else a worker's); the workers keep serving.
    ///
    /// # Panics
    /// If another thread's `run` is in flight (a team has one dispatcher), or the board has
    /// been shut down; in both cases before anything is published.
    pub(crate) fn run(&self, job: &(dyn Fn(usize) + Sync)) -> Result<(), KernelPanic> {
        assert!(
            !self.shutdown.load(Ordering::Acquire),
            "team board used after shut-down"
        );
        assert!(
            !self.in_flight.swap(true, Ordering::Acquire),
            "a team board runs one pass at a time"
        );
        // From opening the pass until no worker is inside it, an unwind out of `run` would
        // end the borrow of `job` under a running worker: the guard turns any unwind in that
        // window into an abort.
        let guard = AbortOnUnwind;
        // SAFETY: no worker reads `job` now: every worker of the previous pass read it before
        // its `fetch_sub` in `serve`, which that pass's `run` saw (its `fetch_and`, or the
        // loads of `wait_for_workers`) before returning — and `in_flight`'s release and
        // acquire carry that to a dispatcher on another thread; none can join until the store
        // below opens this pass, whose release publishes the write to those that join.
        unsafe { *self.pass.job.get() = ErasedJob::new(job) };
        // The previous pass ended with nobody inside and closed, so the word is its epoch.
        let opened =
            (self.pass.word.load(Ordering::Relaxed) & !(OPEN | INSIDE)).wrapping_add(EPOCH);
        // SeqCst, with `workers_asleep` below and in `wait_for_pass`: either a worker going
        // to sleep sees the new epoch, or this thread sees it counted as asleep.
        self.pass.word.store(opened | OPEN, Ordering::SeqCst);
        if self.workers_asleep.load(Ordering::SeqCst) > 0 {
            drop(self.lock());
            self.to_workers.notify_all();
        }
        let own = panic::catch(|| job(0));
        // Close the pass, then wait for the workers inside it. This is what makes the
        // workers' `ErasedJob::call` sound: a worker reads `job` only after its
        // compare-and-swap counted it in, which succeeds only on an open word, and counts
        // itself out only after its call has returned or unwound. Once the `and` below has
        // cleared `OPEN`, no compare-and-swap can succeed until the next `run` opens another
        // pass, so when the count reads zero no thread is inside the job or can enter it.
        // Nothing below can panic (lock poisoning is ignored, and the guard aborts on any
        // unwind all the same), so `run` cannot return before that.
        let inside = self.pass.word.fetch_and(!OPEN, Ordering::AcqRel) & INSIDE;
        if inside > 0 {
            self.wait_for_workers();
        }
        mem::forget(guard);
        // Set by a worker before it counted itself out, which the close or the wait above saw.
        let escaped = if self.panicked.swap(false, Ordering::Relaxed) {
            self.escaped
                .lock()
                .unwrap_or_else(PoisonError::into_inner)
                .take()
        } else {
            None
        };
        self.in_flight.store(false, Ordering::Release);
        match own {
            Err(p) => Err(p),
            Ok(()) => escaped.map_or(Ok(()), Err),
        }
    }

    /// The worker loop of the thread with `index` (1 and up): joins each pass that is still
    /// open when it looks, until [`shut_down`](Self::shut_down).
    pub(crate) fn serve(&self, index: usize) {
        let mut seen = 0;
        while let Some(word) = self.wait_for_pass(seen) {
            seen = epoch(word);
            self.watch.busy(index);
            if !self.join(word) {
                self.watch.away(index);
                continue; // closed before this worker looked: skipped
            }
            let guard = AbortOnUnwind;
            // SAFETY: `join` counted this worker into the open pass, and the `Acquire` of its
            // compare-and-swap makes the dispatcher's write of `job` visible; the dispatcher
            // writes it again only after this worker has counted itself out (see `run`).
            let job = unsafe { *self.pass.job.get() };
            // SAFETY: `job` is the open pass's, whose dispatcher is inside `run`, where the
            // borrow behind it stays alive until this worker counts itself out, below. `catch`
            // keeps an unwinding job from skipping the count-out, and the guard aborts should
            // an unwind escape `catch` all the same.
            let outcome = panic::catch(|| unsafe { job.call(index) });
            if let Err(p) = outcome {
                self.escaped
                    .lock()
                    .unwrap_or_else(PoisonError::into_inner)
                    .get_or_insert(p);
                self.panicked.store(true, Ordering::Relaxed);
            }
            // Counted out: from here on `job` is never read again. SeqCst, with
            // `dispatcher_asleep` in `wait_for_workers`: either the dispatcher sees the count
            // fall, or this thread sees it asleep.
            let before = self.pass.word.fetch_sub(1, Ordering::SeqCst);
            mem::forget(guard);
            let last_out = before & INSIDE == 1 && before & OPEN == 0;
            if last_out && self.dispatcher_asleep.load(Ordering::SeqCst) {
                drop(self.lock());
                self.to_dispatcher.notify_one();
            }
            self.watch.away(index);
        }
    }

    /// Makes every [`serve`](Self::serve) return once it has finished any job in flight, and
    /// makes later [`run`](Self::run)s panic.
    pub(crate) fn shut_down(&self) {
        self.shutdown.store(true, Ordering::SeqCst);
        drop(self.lock());
        self.to_workers.notify_all();
    }

    /// Counts this worker into the pass `word` was read from, if it is still open.
    fn join(&self, mut word: u64) -> bool {
        let opened = epoch(word);
        while word & OPEN != 0 && epoch(word) == opened {
            match self.pass.word.compare_exchange_weak(
                word,
                word + 1,
                Ordering::Acquire,
                Ordering::Relaxed,
            ) {
                Ok(_) => return true,
                Err(now) => word = now,
            }
        }
        false
    }

    /// Waits until a pass after epoch `seen` has been opened (its word), or the board shuts
    /// down (`None`): watching first (see `spin_wait`), then asleep.
    fn wait_for_pass(&self, seen: u64) -> Option<u64> {
        let news = |order| self.shutdown.load(order) || epoch(self.pass.word.load(order)) != seen;
        if !spin_wait::spin_then_yield(spin_wait::LIMIT, || news(Ordering::Acquire)) {
            let mut sleep = self.lock();
            self.workers_asleep.fetch_add(1, Ordering::SeqCst);
            while !news(Ordering::SeqCst) {
                sleep = self
                    .to_workers
                    .wait(sleep)
                    .unwrap_or_else(PoisonError::into_inner);
            }
            self.workers_asleep.fetch_sub(1, Ordering::SeqCst);
        }
        if self.shutdown.load(Ordering::Acquire) {
            return None;
        }
        Some(self.pass.word.load(Ordering::Acquire))
    }

    /// Waits until no worker is inside the closed pass: watching first, then asleep.
    fn wait_for_workers(&self) {
        let drained = |order| self.pass.word.load(order) & INSIDE == 0;
        if self.watch.last_out(LAST_OUT, || drained(Ordering::Acquire)) {
            return;
        }
        let mut sleep = self.lock();
        self.dispatcher_asleep.store(true, Ordering::SeqCst);
        while !drained(Ordering::SeqCst) {
            sleep = self
                .to_dispatcher
                .wait(sleep)
                .unwrap_or_else(PoisonError::into_inner);
        }
        self.dispatcher_asleep.store(false, Ordering::Relaxed);
    }

    /// The lock that sleepers and wakers share; it guards nothing else, so poisoning carries
    /// no meaning.
    fn lock(&self) -> MutexGuard<'_, ()> {
        self.sleep.lock().unwrap_or_else(PoisonError::into_inner)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::erased_job::wait_for;
    use std::collections::HashMap;
    use std::sync::atomic::AtomicUsize;
    use std::thread::{self, ThreadId};
    use std::time::Duration;

    /// Serves a board on `workers` scoped threads (indices 1..) while `f` runs, then shuts
    /// it down; once for each way of waiting.
    fn served(workers: usize, f: impl Fn(&TeamBoard) + Sync) {
        super::super::served(workers, TeamBoard::new, TeamBoard::serve, f);
    }

    #[test]
    fn each_thread_runs_a_job_at_most_once_with_its_index_and_run_waits_for_every_call() {
        served(3, |board| {
            for pass in 1..=20 {
                let calls = Mutex::new(HashMap::<ThreadId, Vec<usize>>::new());
                let (started, ended) = (AtomicUsize::new(0), AtomicUsize::new(0));
                board
                    .run(&|index| {
                        started.fetch_add(1, Ordering::SeqCst);
                        let me = thread::current().id();
                        calls.lock().unwrap().entry(me).or_default().push(index);
                        thread::sleep(Duration::from_micros(300));
                        ended.fetch_add(1, Ordering::SeqCst);
                    })
                    .unwrap();
                let (started, ended) = (started.into_inner(), ended.into_inner());
                assert_eq!(started, ended, "pass {pass}: a call outlived run");
                let calls = calls.into_inner().unwrap();
                assert_eq!(calls[&thread::current().id()], [0], "pass {pass}");
                assert!(calls.len() <= 4, "{calls:?}");
                let mut indices: Vec<usize> = calls.into_values().flatten().collect();
                indices.sort_unstable();
                indices.dedup();
                assert_eq!(indices.len(), started, "an index twice: {indices:?}");
            }
        });
    }

    #[test]
    fn a_pass_does_not_wait_for_a_worker_that_never_comes() {
        served(0, |board| {
            for _ in 0..10 {
                let calls = AtomicUsize::new(0);
                board
                    .run(&|_| {
                        calls.fetch_add(1, Ordering::Relaxed);
                    })
                    .unwrap();
                assert_eq!(calls.into_inner(), 1);
            }
        });
    }

    #[test]
    fn a_sleeping_worker_is_woken_by_a_pass_and_joins_it_while_it_is_open() {
        served(1, |board| {
            // Longer than the watch: the worker is asleep when the pass opens.
            thread::sleep(Duration::from_millis(5));
            for _ in 0..3 {
                let joined = AtomicUsize::new(0);
                board
                    .run(&|index| {
                        if index == 0 {
                            wait_for(|| joined.load(Ordering::SeqCst) == 1);
                        } else {
                            joined.fetch_add(1, Ordering::SeqCst);
                        }
                    })
                    .unwrap();
                thread::sleep(Duration::from_millis(2));
            }
        });
    }

    #[test]
    fn a_job_that_panics_on_a_worker_is_reported_and_the_workers_keep_serving() {
        served(2, |board| {
            let panicked = AtomicUsize::new(0);
            let err = board
                .run(&|index| {
                    if index == 0 {
                        wait_for(|| panicked.load(Ordering::SeqCst) >= 1);
                    } else {
                        panicked.fetch_add(1, Ordering::SeqCst);
                        panic!("team board test panic");
                    }
                })
                .unwrap_err();
            assert_eq!(err.message, "team board test panic");
            // Both workers must still serve: the next pass waits until both have joined.
            let joined = AtomicUsize::new(0);
            board
                .run(&|index| {
                    if index == 0 {
                        wait_for(|| joined.load(Ordering::SeqCst) == 2);
                    } else {
                        joined.fetch_add(1, Ordering::SeqCst);
                    }
                })
                .unwrap();
        });
    }

    #[test]
    fn a_second_dispatcher_is_refused_before_anything_is_published() {
        served(1, |board| {
            let refused = board.run(&|index| {
                if index == 0 {
                    let nested = panic::catch(|| board.run(&|_| {}));
                    assert!(nested.is_err(), "a nested run must be refused");
                }
            });
            assert!(refused.is_ok(), "{refused:?}");
            board.run(&|_| {}).unwrap();
        });
    }
}
