//! `crossbeam-pool`: a pool of `cores` crossbeam threads that lives for the whole run, with
//! chunks handed out dynamically.
//!
//! **Scheduling.** [`Strategy::run`] starts exactly `cores` worker threads in a
//! `crossbeam::scope` and keeps them for the whole session; the session itself runs on the
//! first of them (the calling thread only waits for it). For each pass that thread cuts the
//! output into `min(chunks, len)` balanced chunks, publishes one job on a job board, works on
//! the job itself, and, once it finds no chunk left, waits for the workers still busy with one.
//! The pass's chunks wait in a `crossbeam` `ArrayQueue` (lock-free, bounded, in index order);
//! each thread in the job pops chunks until the queue is empty — so fast workers take more
//! chunks.
//!
//! **What crossbeam does here, and what it does not.** Crossbeam provides the threads
//! (`crossbeam::scope`), the chunk queue and the cache-line padding of the two atomics that
//! waiting threads watch (`CachePadded`, in `erased_job`). The job board itself — publish a job, let the workers
//! that show up join it, close the pass when no chunk is left and wait only for the workers
//! already inside it, sleep after a short watch — is a mutex and two condition variables in
//! `erased_job`, not a channel: a channel delivers each message to one receiver, while every
//! worker must see the same job, and the pass's end must be a rendezvous with exactly the
//! workers that joined it, on which the lifetime erasure's safety argument rests.
//!
//! **Cost.** No thread start-up per pass; per pass one publication and one completion
//! rendezvous, per chunk one push and one pop (a compare-and-swap each), nothing per element.
//! A waiting thread (a worker between passes, the session's thread at the end of a pass)
//! watches an atomic hint for up to 200 µs before it sleeps on a condition variable, so
//! back-to-back passes need no wake-up (waking a sleeping thread costs tens of microseconds,
//! far more on a virtual machine); the watching shows up as CPU time. Where the session's thread
//! spins while it waits (see below), a worker inside a pass also notes its CPU (a
//! `sched_getcpu` and a store to a line of its own, and one more to clear it).
//!
//! **Contention.** The pool must not collapse when its cores are shared (another busy
//! process, more threads than cores). A pass never waits for a worker that has not joined it:
//! the pass closes when the session's thread finds no chunk left, and only the workers already
//! inside it (each busy with a chunk it took) are waited for. A descheduled worker thus costs
//! the pass its help, not a scheduling round-trip. So a worker waiting for the next pass spins
//! a few short rounds and then yields its CPU between checks, leaving it to whichever thread —
//! ours or not — is ready to run, between passes rather than inside one. The session's thread,
//! waiting for the workers inside a pass, holds the pass up (see `spin_wait`): with no more
//! threads than CPUs it spins, as `team`'s does, keeping its CPU — giving it up to another
//! process costs a whole scheduling slice before it comes back — unless a worker it waits for
//! was last seen on its CPU, and then it sleeps at once; with more threads than CPUs the
//! pool's threads share CPUs among themselves, and it yields between checks too, for up to
//! 200 µs (`team`'s, 20 µs). The pool
//! never gives its threads up: every pass offers its chunks to all of them, whatever the
//! machine is doing, so a run does the same work on a busy machine as on a quiet one, and a
//! busy machine shows in its time.
//!
//! **Panics.** A kernel panic is caught per chunk; the first one is returned as
//! [`KernelPanic`] once the pass has finished, and the workers keep serving later passes.
//!
//! **Thread limits and shut-down.** If the operating system refuses a thread, the run fails
//! with [`BuildError::ThreadStart`] before the session starts. Whenever the scope ends — the
//! session returned or unwound, or a thread was refused — a guard first tells the workers to
//! exit, so the scope always joins them.
//!
//! Handing a job borrowed for one pass to threads that outlive it needs lifetime erasure;
//! that `unsafe` is confined to the private module `erased_job`, whose safe API returns only
//! after every worker that joined the pass is done with the job.

use crate::erased_job::{JobBoard, ShutDownOnDrop};
use crate::panic::FirstPanic;
use crate::spin_wait::Watch;
use crate::thread_start::ThreadStarts;
use crate::{
    BuildError, Config, Executor, Info, KernelPanic, Placement, Session, Split, Strategy,
    balanced_chunks,
};
use crossbeam::queue::ArrayQueue;
use std::cell::Cell;
use std::marker::PhantomData;

/// A pool of `cores` long-lived crossbeam scoped threads pulling chunks dynamically.
#[derive(Debug, Clone, Copy)]
pub struct CrossbeamPool {
    cores: usize,
    chunks: usize,
    placement: Placement,
    starts: ThreadStarts,
}

impl Strategy for CrossbeamPool {
    const INFO: Info = Info {
        name: "crossbeam-pool",
        description: "a pool of --cores crossbeam threads kept for the whole run (the steps \
                      run on one of them); each pass's chunks are popped dynamically from a \
                      crossbeam queue",
        calls: crate::Calls::Chunks,
    };

    fn build(config: &Config) -> Result<Self, BuildError> {
        config.validate()?;
        Ok(CrossbeamPool {
            cores: config.cores,
            chunks: config.chunks,
            placement: config.placement,
            starts: ThreadStarts::default(),
        })
    }

    /// Starts the workers, runs `session` on the first of them, then stops and joins the
    /// others.
    ///
    /// # Panics
    /// Re-raises a panic of `session` itself once the workers have been joined.
    fn run<S: Session>(&self, session: S) -> Result<S::Output, BuildError> {
        let board = JobBoard::new(Watch::for_team(self.cores, self.placement));
        let executor = PoolExecutor {
            board: &board,
            threads: self.cores,
            chunks: self.chunks,
            not_sync: PhantomData,
        };
        let (cores, placement) = (self.cores, self.placement);
        let board = &board;
        let outcome = crossbeam::scope(|scope| {
            // Created before the first worker, so that every way out of this closure — a
            // return, a refused thread, a panicking session — releases the workers first.
            let _stop = ShutDownOnDrop(board);
            for i in 1..cores {
                self.starts.start(i, cores, || {
                    scope
                        .builder()
                        .name(format!("crossbeam-pool-{i}"))
                        .spawn(move |_| {
                            placement.on_start(i);
                            board.serve(i)
                        })
                })?;
            }
            let session_thread = self.starts.start(0, cores, || {
                scope
                    .builder()
                    .name("crossbeam-pool-0".to_owned())
                    .spawn(move |_| {
                        placement.on_start(0);
                        session.run(&executor)
                    })
            })?;
            Ok(session_thread.join())
        })
        // A serving thread cannot panic: `serve` catches whatever a job throws.
        .expect("a crossbeam-pool worker thread panicked");
        outcome.map(|joined| joined.unwrap_or_else(|payload| std::panic::resume_unwind(payload)))
    }
}

/// Publishes each pass on the board.
///
/// Deliberately not `Sync`: a kernel (which must be `Sync`) therefore cannot capture the
/// executor and start a nested pass from a worker, which would wait for itself forever.
struct PoolExecutor<'a> {
    board: &'a JobBoard,
    /// The pool's threads, the session's included.
    threads: usize,
    chunks: usize,
    not_sync: PhantomData<Cell<()>>,
}

impl Executor for PoolExecutor<'_> {
    fn for_each_chunk<O, F>(&self, out: O, kernel: F) -> Result<(), KernelPanic>
    where
        O: Split,
        F: Fn(usize, O) + Sync,
    {
        if out.is_empty() {
            return Ok(());
        }
        let chunks = balanced_chunks(out, self.chunks);
        // Not empty (`out` is not), so the capacity is at least 1 as `ArrayQueue` requires.
        let queue = ArrayQueue::new(chunks.len());
        for chunk in chunks {
            if queue.push(chunk).is_err() {
                unreachable!("the queue holds exactly the pass's chunks");
            }
        }
        let panics = FirstPanic::default();

        // Run by every worker: pop chunks (each one exactly once, in index order) until none
        // is left. A panicking kernel is caught here; the first panic is kept.
        let job = || {
            while let Some((first, chunk)) = queue.pop() {
                panics.catch(|| kernel(first, chunk));
            }
        };
        let escaped = self.board.run(&job);
        panics.or(escaped)
    }

    fn threads(&self) -> usize {
        self.threads
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing::{distinct, run_counting, thread_ids_per_pass};

    #[test]
    fn passes_are_spread_over_more_than_one_thread() {
        let passes = thread_ids_per_pass::<CrossbeamPool>(2, 16, 16, 1);
        assert!(distinct(&passes[0]) > 1, "{passes:?}");
    }

    #[test]
    fn the_same_workers_serve_every_pass_and_the_caller_computes_nothing() {
        let passes = thread_ids_per_pass::<CrossbeamPool>(3, 64, 64, 10);
        let all: Vec<_> = passes.concat();
        assert!(distinct(&all) <= 3, "{passes:?}");
        assert!(!all.contains(&std::thread::current().id()));
    }

    #[test]
    fn a_worker_thread_the_system_refuses_fails_the_run_before_the_session_starts() {
        // Thread 1 runs the session and is started last; threads 2..4 serve the board.
        for (refuse, message) in [
            (2, "could not start worker thread 3 of 4"),
            (0, "could not start worker thread 1 of 4"),
        ] {
            let strategy = CrossbeamPool {
                cores: 4,
                chunks: 8,
                placement: Placement::OS,
                starts: ThreadStarts {
                    refuse: Some(refuse),
                },
            };
            // The workers are scoped threads: `run` returning (within the watchdog) means the
            // ones already started were told to stop and have been joined.
            let counted = run_counting(strategy, 100, 5);
            let err = counted.run.expect_err("the refused thread is an error");
            assert_eq!(err.to_string(), message);
            assert_eq!((counted.started, counted.ended), (0, 0), "{message}");
        }
    }
}
