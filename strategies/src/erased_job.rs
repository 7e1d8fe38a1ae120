//! The one place in the workspace with `unsafe`: handing a job borrowed for one pass to
//! long-lived worker threads.
//!
//! Safe Rust cannot give a thread that outlives a borrow a reference to the borrowed data,
//! even when we know the thread stops using it before the borrow ends. A [`JobBoard`] does
//! exactly that and nothing else: [`JobBoard::run`] publishes a `&(dyn Fn() + Sync)` with its
//! lifetime erased, every thread serving the board calls it once, and `run` returns only after
//! every one of them has said it is done with it.
//!
//! The soundness argument lives entirely in this file, behind a safe API: no caller can make
//! the board call a job after `run` has returned, whatever the job does (a job that panics is
//! caught on the worker, which still signals completion and keeps serving) and whatever the
//! callers do (concurrent `run`s are serialised; a shut-down board refuses new jobs; extra
//! serving threads are counted like the others). The worst a misuse can cause is a hang —
//! e.g. a board created for more workers than serve it — never a dangling reference.

#![allow(unsafe_code)]

use std::mem;
use std::ptr::NonNull;
use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering};
use std::sync::{Condvar, Mutex, MutexGuard, PoisonError};
use std::time::{Duration, Instant};

use crate::{KernelPanic, panic};

/// A `&(dyn Fn() + Sync)` whose lifetime has been erased. Only [`JobBoard`] creates and calls
/// one, and only while the borrow it came from is alive (see [`JobBoard::run`]).
#[derive(Clone, Copy)]
struct ErasedJob(NonNull<dyn Fn() + Sync + 'static>);

// SAFETY: an `ErasedJob` is a shared reference to a `Sync` closure, and `&T` is `Send` when
// `T: Sync`. The lifetime it lost is upheld by `JobBoard`'s protocol, not by the type.
unsafe impl Send for ErasedJob {}

impl ErasedJob {
    /// Erases the lifetime of `job`.
    fn new<'a>(job: &'a (dyn Fn() + Sync + 'a)) -> Self {
        let ptr: NonNull<dyn Fn() + Sync + 'a> = NonNull::from(job);
        // SAFETY: both types are the same fat pointer and differ only in the trait object's
        // lifetime bound, so the layout is identical. Creating the pointer is harmless; it is
        // dereferenced only in `call`, whose contract keeps it within `'a`.
        let ptr: NonNull<dyn Fn() + Sync + 'static> = unsafe { mem::transmute(ptr) };
        ErasedJob(ptr)
    }

    /// Calls the job.
    ///
    /// # Safety
    /// The borrow that `self` was created from must still be alive.
    unsafe fn call(self) {
        // SAFETY: the pointer came from a valid shared reference (`new`) and, by this
        // function's contract, that reference's borrow has not ended yet.
        let job = unsafe { self.0.as_ref() };
        job();
    }
}

/// What the dispatcher and the workers share, behind one mutex.
struct State {
    /// The job of the pass in flight; `Some` from publication until every worker is done.
    job: Option<ErasedJob>,
    /// Bumped once per published job; a worker runs a job when this differs from the epoch
    /// it last looked at.
    epoch: u64,
    /// Workers inside the job in flight right now.
    running: usize,
    /// Workers that have finished the job in flight.
    finished: usize,
    /// The first panic that escaped the job in flight.
    escaped: Option<KernelPanic>,
    /// Set once, when the workers must exit.
    shutdown: bool,
    /// Workers asleep on `to_workers`, and dispatchers asleep on `to_dispatcher`: a
    /// notification (a system call) is sent only when someone sleeps.
    asleep: Sleepers,
}

/// Threads asleep on each condition variable.
#[derive(Default)]
struct Sleepers {
    workers: usize,
    dispatchers: usize,
}

/// How long a thread spins, watching the hints, before it sleeps on a condition variable:
/// passes follow each other within microseconds, and waking a sleeping thread costs tens of
/// microseconds (more on a virtual machine).
const SPIN: Duration = Duration::from_micros(200);

/// A rendezvous between one dispatching thread and a fixed number of worker threads.
///
/// Exactly `workers` threads must call [`serve`](Self::serve); [`run`](Self::run) then runs a
/// job once on each of them and once on the dispatcher itself, and
/// [`shut_down`](Self::shut_down) makes `serve` return.
///
/// Every decision is taken under the mutex. Two atomics mirror parts of the state as hints,
/// so that a waiting thread can spin without taking the lock before it falls back to its
/// condition variable; a stale hint only costs a lock, never a decision.
pub(crate) struct JobBoard {
    workers: usize,
    state: Mutex<State>,
    /// Hint: `State::epoch`, bumped again at shut-down.
    epoch_hint: AtomicU64,
    /// Hint: `State::finished` of the job in flight.
    finished_hint: AtomicUsize,
    /// Wakes workers: a job was published, or the board shut down.
    to_workers: Condvar,
    /// Wakes dispatchers: the pass in flight finished.
    to_dispatcher: Condvar,
}

impl JobBoard {
    /// A board for exactly `workers` serving threads (0 is allowed: the dispatcher then runs
    /// each job alone).
    pub(crate) fn new(workers: usize) -> Self {
        JobBoard {
            workers,
            epoch_hint: AtomicU64::new(0),
            finished_hint: AtomicUsize::new(0),
            state: Mutex::new(State {
                job: None,
                epoch: 0,
                running: 0,
                finished: 0,
                escaped: None,
                shutdown: false,
                asleep: Sleepers::default(),
            }),
            to_workers: Condvar::new(),
            to_dispatcher: Condvar::new(),
        }
    }

    /// Runs `job` once on every worker and once on the calling thread, and returns when all of
    /// them have finished it.
    ///
    /// A panic that escapes `job` (on a worker or here) is caught and returned (the first one,
    /// if several); the workers keep serving. Calls from several threads are serialised.
    ///
    /// # Panics
    /// If the board has been shut down (its workers are gone, so the job could never run).
    pub(crate) fn run(&self, job: &(dyn Fn() + Sync)) -> Result<(), KernelPanic> {
        let mut state = self.lock();
        // Another thread's pass is in flight: wait for it, so the counts are only ours.
        while state.job.is_some() {
            state = self.wait_as_dispatcher(state);
        }
        assert!(!state.shutdown, "job board used after shut-down");
        state.job = Some(ErasedJob::new(job));
        state.epoch += 1;
        state.finished = 0;
        state.escaped = None;
        self.finished_hint.store(0, Ordering::Relaxed);
        self.epoch_hint.store(state.epoch, Ordering::Release);
        let wake_workers = state.asleep.workers > 0;
        drop(state);
        if wake_workers {
            self.to_workers.notify_all();
        }
        // The dispatcher's own share: a plain call through the live borrow. Its panic is
        // caught, and the guard turns any unwind that still escapes into an abort, so that
        // the wait below can never be skipped.
        let guard = AbortOnUnwind;
        let own = panic::catch(job);
        mem::forget(guard);
        let mut state = self.lock();
        if let Err(p) = own {
            state.escaped.get_or_insert(p);
        }
        // This loop is what makes `ErasedJob::call` sound: `job`'s borrow lasts at least until
        // this function returns, and it cannot return (nothing below can panic: lock poisoning
        // is ignored) while `running > 0`, a condition only ever checked under the lock. A
        // worker increments `running` under the lock when it takes the job, and decrements it
        // under the lock only after its call has returned or unwound; once `job` is cleared
        // below (in the same critical section that saw `running == 0`), no worker can take it
        // again. Waiting for `finished` as well is for correctness — every worker runs the
        // job — not for soundness, which holds even if more or fewer threads serve the board
        // than `workers`.
        while state.finished < self.workers || state.running > 0 {
            drop(state);
            spin_until(|| self.finished_hint.load(Ordering::Acquire) >= self.workers);
            state = self.lock();
            if state.finished < self.workers || state.running > 0 {
                state = self.wait_as_dispatcher(state);
            }
        }
        state.job = None;
        let escaped = state.escaped.take();
        let wake_dispatchers = state.asleep.dispatchers > 0;
        drop(state);
        // Let a dispatcher that waited for this pass publish its own.
        if wake_dispatchers {
            self.to_dispatcher.notify_all();
        }
        escaped.map_or(Ok(()), Err)
    }

    /// The worker loop: runs each published job once, until [`shut_down`](Self::shut_down).
    ///
    /// A job published before the shut-down is still run, so a pass in flight always ends.
    pub(crate) fn serve(&self) {
        let mut seen = 0;
        loop {
            let job = {
                let mut state = self.lock();
                loop {
                    if state.epoch != seen {
                        seen = state.epoch;
                        // With exactly `workers` serving threads the job is always still
                        // there; with more, a pass may have ended before this one looked.
                        if let Some(job) = state.job {
                            state.running += 1;
                            break job;
                        }
                    }
                    if state.shutdown {
                        return;
                    }
                    drop(state);
                    spin_until(|| self.epoch_hint.load(Ordering::Acquire) != seen);
                    state = self.lock();
                    if state.epoch == seen && !state.shutdown {
                        state = self.wait_as_worker(state);
                    }
                }
            };

            // SAFETY: this worker counted itself in `running` when it took `job` and has not
            // yet counted itself out, so the dispatcher is still inside `run`, where the borrow
            // behind `job` is alive (see the comment on the wait loop there). `catch` keeps an
            // unwinding job from skipping the count-out below, and the guard aborts should an
            // unwind escape `catch` all the same.
            let guard = AbortOnUnwind;
            let outcome = panic::catch(|| unsafe { job.call() });
            mem::forget(guard);

            // From here on `job` is never called again; the next iteration overwrites it.
            let mut state = self.lock();
            if let Err(p) = outcome {
                state.escaped.get_or_insert(p);
            }
            state.running -= 1;
            state.finished += 1;
            self.finished_hint.store(state.finished, Ordering::Release);
            if state.running == 0 && state.finished >= self.workers && state.asleep.dispatchers > 0
            {
                self.to_dispatcher.notify_all();
            }
        }
    }

    /// Makes every [`serve`](Self::serve) return once it has finished any job in flight, and
    /// makes later [`run`](Self::run)s panic.
    pub(crate) fn shut_down(&self) {
        let mut state = self.lock();
        state.shutdown = true;
        self.epoch_hint.store(state.epoch + 1, Ordering::Release);
        drop(state);
        self.to_workers.notify_all();
    }

    /// Locks the state. Nothing panics while holding the lock except `run`'s shut-down
    /// assertion, which has changed nothing by then, so poisoning carries no meaning here and
    /// is ignored.
    fn lock(&self) -> MutexGuard<'_, State> {
        self.state.lock().unwrap_or_else(PoisonError::into_inner)
    }

    /// Sleeps on `to_workers`, counted as a sleeping worker.
    fn wait_as_worker<'g>(&self, mut state: MutexGuard<'g, State>) -> MutexGuard<'g, State> {
        state.asleep.workers += 1;
        let mut state = self.wait(&self.to_workers, state);
        state.asleep.workers -= 1;
        state
    }

    /// Sleeps on `to_dispatcher`, counted as a sleeping dispatcher.
    fn wait_as_dispatcher<'g>(&self, mut state: MutexGuard<'g, State>) -> MutexGuard<'g, State> {
        state.asleep.dispatchers += 1;
        let mut state = self.wait(&self.to_dispatcher, state);
        state.asleep.dispatchers -= 1;
        state
    }

    fn wait<'g>(&self, cv: &Condvar, guard: MutexGuard<'g, State>) -> MutexGuard<'g, State> {
        cv.wait(guard).unwrap_or_else(PoisonError::into_inner)
    }
}

/// Aborts the process when dropped. Armed around the calls of a job and disarmed with
/// `mem::forget` after them, so only an unwind that escaped `panic::catch` reaches it: going
/// on would skip the bookkeeping that keeps an erased job from outliving its borrow.
struct AbortOnUnwind;

impl Drop for AbortOnUnwind {
    fn drop(&mut self) {
        std::process::abort();
    }
}

/// Spins until `done()` or until [`SPIN`] has passed. `done` is checked after every pause
/// (one `PAUSE` can take over a hundred cycles); the clock only every 64 of them.
fn spin_until(done: impl Fn() -> bool) {
    let start = Instant::now();
    loop {
        for _ in 0..64 {
            if done() {
                return;
            }
            std::hint::spin_loop();
        }
        if start.elapsed() > SPIN {
            return;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::atomic::{AtomicUsize, Ordering};

    #[test]
    fn every_worker_runs_each_job_once_and_run_waits_for_all_of_them() {
        let board = JobBoard::new(3);
        std::thread::scope(|s| {
            for _ in 0..3 {
                s.spawn(|| board.serve());
            }
            for pass in 1..=10 {
                let calls = AtomicUsize::new(0);
                board
                    .run(&|| {
                        std::thread::sleep(std::time::Duration::from_micros(200));
                        calls.fetch_add(1, Ordering::Relaxed);
                    })
                    .unwrap();
                // Once on each of the three workers and once on the dispatcher.
                assert_eq!(calls.load(Ordering::Relaxed), 4, "pass {pass}");
            }
            board.shut_down();
        });
    }

    #[test]
    fn a_job_that_panics_is_reported_and_the_workers_keep_serving() {
        let board = JobBoard::new(2);
        std::thread::scope(|s| {
            for _ in 0..2 {
                s.spawn(|| board.serve());
            }
            let err = board.run(&|| panic!("job board test panic")).unwrap_err();
            assert_eq!(err.message, "job board test panic");
            let calls = AtomicUsize::new(0);
            board
                .run(&|| {
                    calls.fetch_add(1, Ordering::Relaxed);
                })
                .unwrap();
            assert_eq!(calls.load(Ordering::Relaxed), 3);
            board.shut_down();
        });
    }

    #[test]
    fn runs_from_several_threads_are_serialised() {
        let board = JobBoard::new(2);
        let calls = AtomicUsize::new(0);
        std::thread::scope(|s| {
            for _ in 0..2 {
                s.spawn(|| board.serve());
            }
            let dispatchers: Vec<_> = (0..4)
                .map(|_| {
                    s.spawn(|| {
                        for _ in 0..50 {
                            board
                                .run(&|| {
                                    calls.fetch_add(1, Ordering::Relaxed);
                                })
                                .unwrap();
                        }
                    })
                })
                .collect();
            for d in dispatchers {
                d.join().unwrap();
            }
            board.shut_down();
        });
        assert_eq!(calls.load(Ordering::Relaxed), 4 * 50 * 3);
    }

    #[test]
    fn run_never_returns_while_a_surplus_worker_is_still_inside_the_job() {
        // Declared for one worker but served by three: every pass must still wait for every
        // worker that took the job.
        let board = JobBoard::new(1);
        std::thread::scope(|s| {
            for _ in 0..3 {
                s.spawn(|| board.serve());
            }
            for _ in 0..50 {
                let started = AtomicUsize::new(0);
                let ended = AtomicUsize::new(0);
                board
                    .run(&|| {
                        started.fetch_add(1, Ordering::SeqCst);
                        std::thread::sleep(std::time::Duration::from_micros(300));
                        ended.fetch_add(1, Ordering::SeqCst);
                    })
                    .unwrap();
                let (started, ended) = (started.into_inner(), ended.into_inner());
                assert!(
                    started >= 1 && started == ended,
                    "{started} started, {ended} ended"
                );
            }
            board.shut_down();
        });
    }
}
