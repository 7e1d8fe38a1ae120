//! [`JobBoard`]: a job borrowed for one pass, run by whichever serving threads join the pass
//! while it is open (`crossbeam-pool`'s board).
//!
//! Besides its books, each worker notes in a slot of its own the CPU it works on while it is
//! inside a job (`whereabouts`), for the dispatcher's watch before it sleeps
//! (`spin_wait::Watch`), as on `team`'s board.

use std::mem;
use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering};
use std::sync::{Condvar, Mutex, MutexGuard, PoisonError};

use crossbeam::utils::CachePadded;

use super::{AbortOnUnwind, ErasedJob};
use crate::spin_wait::{self, Watch};
use crate::{KernelPanic, panic};

/// What the dispatcher and the workers share, behind one mutex.
struct State {
    /// The job of the open pass: `Some` from publication until the dispatcher's own call of
    /// it has returned. A worker can join a pass only while it is open.
    job: Option<ErasedJob>,
    /// Bumped once per published job; a worker looks for a job when this differs from the
    /// epoch it last looked at.
    epoch: u64,
    /// Workers inside the job right now.
    running: usize,
    /// A `run` is between publishing its job and returning: later `run`s wait for it.
    in_flight: bool,
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

/// A rendezvous between a dispatching thread and the worker threads that serve the board.
///
/// Any number of threads may call [`serve`](Self::serve) (none at all, too), each with an index
/// of its own from 1, its slot in the watch (0 is the dispatcher's, which it never notes);
/// [`run`](Self::run)
/// runs a job on the calling thread and on every worker that joins while the pass is open, and
/// [`shut_down`](Self::shut_down) makes `serve` return.
///
/// **The pass waits only for those who came.** The dispatcher closes the pass as soon as its
/// own call of the job returns, and then waits only for the workers inside the job. A worker
/// that is slow to notice a pass — asleep, or descheduled because another process wants its
/// core — simply skips it, instead of holding every pass up until the scheduler runs it
/// again. A job must therefore *help until done*: any one call finishes whatever work nobody
/// else has taken (the pool's job pops chunks from a queue until none is left), so the
/// work is complete once the dispatcher's call has returned and everyone who joined has left.
///
/// **Waiting.** A waiting thread first watches an atomic hint — a worker spinning briefly, then
/// yielding its core between checks; the dispatcher, waiting for the last workers of a pass,
/// as its [`Watch`] says (see `spin_wait`) — and sleeps on a condition variable after that.
/// Every decision is taken under the mutex; a stale hint only costs a lock.
pub(crate) struct JobBoard {
    state: Mutex<State>,
    /// Hint: `State::epoch`, bumped again at shut-down. Watched by idle workers; padded to a
    /// cache line of its own, so that workers leaving a pass (which write `running_hint`) do
    /// not disturb it.
    epoch_hint: CachePadded<AtomicU64>,
    /// Hint: `State::running`. Watched by the dispatcher at the end of a pass.
    running_hint: CachePadded<AtomicUsize>,
    /// Wakes workers: a job was published, or the board shut down.
    to_workers: Condvar,
    /// Wakes dispatchers: the workers left a closed pass, or a `run` returned.
    to_dispatcher: Condvar,
    /// How the dispatcher watches for the last workers of a pass, and where the workers inside
    /// a pass run.
    watch: Watch,
}

impl JobBoard {
    /// A board with no job yet, whose dispatcher watches as `watch` says.
    pub(crate) fn new(watch: Watch) -> Self {
        JobBoard {
            epoch_hint: CachePadded::new(AtomicU64::new(0)),
            running_hint: CachePadded::new(AtomicUsize::new(0)),
            state: Mutex::new(State {
                job: None,
                epoch: 0,
                running: 0,
                in_flight: false,
                escaped: None,
                shutdown: false,
                asleep: Sleepers::default(),
            }),
            to_workers: Condvar::new(),
            to_dispatcher: Condvar::new(),
            watch,
        }
    }

    /// Runs `job` on the calling thread and on every worker that joins while the pass is open
    /// (each at most once), and returns when all of those calls have finished.
    ///
    /// The pass closes when the calling thread's own call returns; `job` must help until done
    /// (see [`JobBoard`]). A panic that escapes `job` (on a worker or here) is caught and
    /// returned (the first one, if several); the workers keep serving. Calls from several
    /// threads are serialised.
    ///
    /// # Panics
    /// If the board has been shut down (its workers are gone).
    pub(crate) fn run(&self, job: &(dyn Fn() + Sync)) -> Result<(), KernelPanic> {
        let mut state = self.lock();
        // Another thread's pass is in flight: wait for it, so the counts are only ours.
        while state.in_flight {
            state = self.wait_as_dispatcher(state);
        }
        assert!(!state.shutdown, "job board used after shut-down");
        // From publishing the job until no worker is inside it, an unwind out of `run` would
        // free the job's borrow under a running worker: the guard turns any unwind in that
        // window (even one from a clock read while waiting) into an abort.
        let guard = AbortOnUnwind;
        state.in_flight = true;
        // The board's jobs take no index: every thread that joins runs the same call.
        let indexed = |_: usize| job();
        state.job = Some(ErasedJob::new(&indexed));
        state.epoch += 1;
        state.escaped = None;
        self.epoch_hint.store(state.epoch, Ordering::Release);
        let wake_workers = state.asleep.workers > 0;
        drop(state);
        if wake_workers {
            self.to_workers.notify_all();
        }
        // The dispatcher's own share: a plain call through the live borrow. (`indexed`, which
        // the workers call, lives until `run` returns, after the wait below.) Its panic is
        // caught; an unwind that still escapes aborts (the guard above), so that the wait
        // below can never be skipped.
        let own = panic::catch(job);
        let mut state = self.lock();
        if let Err(p) = own {
            state.escaped.get_or_insert(p);
        }
        // Close the pass, then wait for the workers inside it. This is what makes
        // `ErasedJob::call` sound: `job`'s borrow lasts at least until this function returns.
        // A worker can take the job only under the lock while `state.job` holds it, and
        // counts itself into `running` in that same critical section; it counts itself out,
        // under the lock, only after its call has returned or unwound. Once `job` is withdrawn
        // here, nobody can take it again, so when the loop below sees `running == 0` under the
        // lock, no thread is inside the job or can enter it. Nothing below can panic (lock
        // poisoning is ignored, and the guard aborts on any unwind all the same), so `run`
        // cannot return before that. This holds whatever number of threads serve the board.
        state.job = None;
        while state.running > 0 {
            drop(state);
            let drained = || self.running_hint.load(Ordering::Acquire) == 0;
            self.watch.last_out(spin_wait::LIMIT, drained);
            state = self.lock();
            if state.running > 0 {
                state = self.wait_as_dispatcher(state);
            }
        }
        mem::forget(guard);
        state.in_flight = false;
        let escaped = state.escaped.take();
        let wake_dispatchers = state.asleep.dispatchers > 0;
        drop(state);
        // Let a dispatcher that waited for this pass publish its own.
        if wake_dispatchers {
            self.to_dispatcher.notify_all();
        }
        escaped.map_or(Ok(()), Err)
    }

    /// The worker loop of the thread with `index` (1 and up): joins each pass that is still
    /// open when it looks, until [`shut_down`](Self::shut_down).
    ///
    /// A job taken before the shut-down is still finished, so a pass in flight always ends.
    pub(crate) fn serve(&self, index: usize) {
        let mut seen = 0;
        loop {
            let job = {
                let mut state = self.lock();
                loop {
                    if state.epoch != seen {
                        seen = state.epoch;
                        // A pass that closed before this worker looked is skipped.
                        if let Some(job) = state.job {
                            // Noted before it counts in, under the lock: a dispatcher that
                            // finds it inside the pass finds where it runs too.
                            self.watch.busy(index);
                            state.running += 1;
                            self.running_hint.store(state.running, Ordering::Relaxed);
                            break job;
                        }
                    }
                    if state.shutdown {
                        return;
                    }
                    drop(state);
                    let news = || self.epoch_hint.load(Ordering::Acquire) != seen;
                    spin_wait::spin_then_yield(spin_wait::LIMIT, news);
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
            let outcome = panic::catch(|| unsafe { job.call(0) });

            // From here on `job` is never called again; the next iteration overwrites it.
            let mut state = self.lock();
            if let Err(p) = outcome {
                state.escaped.get_or_insert(p);
            }
            state.running -= 1;
            self.running_hint.store(state.running, Ordering::Release);
            // Counted out: an unwind from here on could no longer leave the dispatcher waiting.
            mem::forget(guard);
            // Only a dispatcher whose pass is closed waits for `running` to reach zero.
            if state.running == 0 && state.job.is_none() && state.asleep.dispatchers > 0 {
                self.to_dispatcher.notify_all();
            }
            drop(state);
            self.watch.away(index);
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::erased_job::wait_for;
    use std::collections::HashMap;
    use std::sync::atomic::{AtomicUsize, Ordering};
    use std::thread::{self, ThreadId};
    use std::time::Duration;

    /// Serves a board on `workers` scoped threads while `f` runs, then shuts it down; once for
    /// each way of waiting.
    fn served(workers: usize, f: impl Fn(&JobBoard) + Sync) {
        super::super::served(workers, JobBoard::new, JobBoard::serve, f);
    }

    #[test]
    fn each_thread_runs_a_job_at_most_once_and_run_waits_for_every_call_that_started() {
        served(3, |board| {
            for pass in 1..=20 {
                let calls = Mutex::new(HashMap::<ThreadId, usize>::new());
                let (started, ended) = (AtomicUsize::new(0), AtomicUsize::new(0));
                board
                    .run(&|| {
                        started.fetch_add(1, Ordering::SeqCst);
                        *calls
                            .lock()
                            .unwrap()
                            .entry(thread::current().id())
                            .or_default() += 1;
                        thread::sleep(Duration::from_micros(300));
                        ended.fetch_add(1, Ordering::SeqCst);
                    })
                    .unwrap();
                let (started, ended) = (started.into_inner(), ended.into_inner());
                assert_eq!(started, ended, "pass {pass}: a call outlived run");
                let calls = calls.into_inner().unwrap();
                assert!(calls.contains_key(&thread::current().id()), "pass {pass}");
                assert!(
                    calls.len() <= 4 && calls.values().all(|&n| n == 1),
                    "{calls:?}"
                );
            }
        });
    }

    #[test]
    fn a_pass_does_not_wait_for_a_worker_that_never_comes() {
        // The board is served by nobody: each pass is the dispatcher's alone, and ends.
        served(0, |board| {
            for _ in 0..10 {
                let calls = AtomicUsize::new(0);
                board
                    .run(&|| {
                        calls.fetch_add(1, Ordering::Relaxed);
                    })
                    .unwrap();
                assert_eq!(calls.into_inner(), 1);
            }
        });
    }

    #[test]
    fn a_worker_joins_a_pass_that_is_still_open() {
        // The dispatcher's call waits until a worker has joined, which only a worker that sees
        // the open pass can do.
        served(1, |board| {
            let dispatcher = thread::current().id();
            let joined = AtomicUsize::new(0);
            board
                .run(&|| {
                    if thread::current().id() == dispatcher {
                        wait_for(|| joined.load(Ordering::SeqCst) == 1);
                    } else {
                        joined.fetch_add(1, Ordering::SeqCst);
                    }
                })
                .unwrap();
            assert_eq!(joined.into_inner(), 1);
        });
    }

    #[test]
    fn a_job_that_panics_on_a_worker_is_reported_and_the_workers_keep_serving() {
        served(2, |board| {
            let dispatcher = thread::current().id();
            let panicked = AtomicUsize::new(0);
            let err = board
                .run(&|| {
                    if thread::current().id() == dispatcher {
                        wait_for(|| panicked.load(Ordering::SeqCst) >= 1);
                    } else {
                        panicked.fetch_add(1, Ordering::SeqCst);
                        panic!("job board test panic");
                    }
                })
                .unwrap_err();
            assert_eq!(err.message, "job board test panic");
            // Both workers must still serve: the next pass waits until both have joined.
            let joined = AtomicUsize::new(0);
            board
                .run(&|| {
                    if thread::current().id() == dispatcher {
                        wait_for(|| joined.load(Ordering::SeqCst) == 2);
                    } else {
                        joined.fetch_add(1, Ordering::SeqCst);
                    }
                })
                .unwrap();
        });
    }

    #[test]
    fn runs_from_several_threads_are_serialised() {
        // (pass, calls inside it now): a call of one pass never overlaps a call of another.
        let inside = Mutex::new((0usize, 0usize));
        served(2, |board| {
            thread::scope(|s| {
                for d in 0..4 {
                    let inside = &inside;
                    s.spawn(move || {
                        for i in 0..50 {
                            let pass = 1 + d * 1000 + i;
                            board
                                .run(&|| {
                                    {
                                        let mut g = inside.lock().unwrap();
                                        assert!(g.1 == 0 || g.0 == pass, "passes overlap");
                                        *g = (pass, g.1 + 1);
                                    }
                                    thread::yield_now();
                                    inside.lock().unwrap().1 -= 1;
                                })
                                .unwrap();
                        }
                    });
                }
            });
        });
        assert_eq!(inside.into_inner().unwrap().1, 0);
    }
}
