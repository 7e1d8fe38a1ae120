//! `team`: an OpenMP-style team — `cores` threads kept for the whole run, each pass cut into
//! one contiguous block per thread, and a barrier between passes that spins, then sleeps.
//!
//! **Scheduling.** [`Strategy::run`] starts exactly `cores` threads once per run and keeps
//! them; the session runs on the first (thread 0; the calling thread only waits for it).
//! Each pass is cut into `min(cores, len)` balanced contiguous blocks, and thread `i` takes
//! block `i`: with every thread present, that is a static partition, the same block on the
//! same thread pass after pass, as `#pragma omp parallel for schedule(static)`. A thread that
//! has finished its own block takes any block nobody has started (the next ones first), so a
//! thread that is late — asleep, or descheduled because another process wants its core —
//! costs the pass its help, not a wait: the pass ends once every block is done and every
//! thread that took one has left.
//!
//! **Cost.** No thread start-up per pass. Per pass the session's thread opens the pass with
//! one atomic store and closes it with one read-modify-write; a worker joins with one
//! compare-and-swap and leaves with one subtraction (`TeamBoard`, in `erased_job`); each
//! block is claimed with one swap on its own flag. No lock, no queue, nothing per element.
//! Between passes a thread watches the pass word for up to 200 µs (spinning, then yielding
//! its core between checks; see `spin_wait`) before it sleeps on a condition variable, so
//! back-to-back passes need no wake-up; the watching shows up as CPU time.
//!
//! **Panics.** A kernel panic is caught per block; the first one is returned as
//! [`KernelPanic`] once the pass has finished, and the threads keep serving later passes.
//!
//! **Thread limits and shut-down.** As `crossbeam-pool`: a refused thread fails the run with
//! [`BuildError::ThreadStart`] before the session starts, and whenever the scope ends a
//! guard first tells the threads to exit, so the scope always joins them.

use std::cell::Cell;
use std::marker::PhantomData;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Mutex, OnceLock, PoisonError};

use crate::erased_job::TeamBoard;
use crate::thread_start::ThreadStarts;
use crate::{
    BuildError, Config, Executor, Info, KernelPanic, Placement, Session, Split, Strategy,
    balanced_chunks, panic,
};

/// `cores` threads kept for the run, one contiguous block of each pass per thread.
#[derive(Debug, Clone, Copy)]
pub struct Team {
    cores: usize,
    placement: Placement,
    starts: ThreadStarts,
}

impl Strategy for Team {
    const INFO: Info = Info {
        name: "team",
        description: "an OpenMP-style team: --cores threads kept for the whole run (the \
                      steps run on one of them), each pass cut into one contiguous block per \
                      thread, a spinning barrier between passes; a late thread's block is \
                      taken by whoever is free",
        calls: crate::Calls::Blocks,
    };

    fn build(config: &Config) -> Result<Self, BuildError> {
        config.validate()?;
        Ok(Team {
            cores: config.cores,
            placement: config.placement,
            starts: ThreadStarts::default(),
        })
    }

    /// Starts the threads, runs `session` on the first of them, then stops and joins the
    /// others.
    ///
    /// # Panics
    /// Re-raises a panic of `session` itself once the threads have been joined.
    fn run<S: Session>(&self, session: S) -> Result<S::Output, BuildError> {
        let board = TeamBoard::new();
        let executor = TeamExecutor {
            board: &board,
            threads: self.cores,
            not_sync: PhantomData,
        };
        let (cores, placement, board) = (self.cores, self.placement, &board);
        std::thread::scope(|scope| {
            // Created before the first worker, so that every way out of this closure — a
            // return, a refused thread, a panicking session — releases the workers first.
            let _stop = ShutDownOnDrop(board);
            for i in 1..cores {
                self.starts.start(i, cores, || {
                    std::thread::Builder::new()
                        .name(format!("team-{i}"))
                        .spawn_scoped(scope, move || {
                            placement.on_start(i);
                            board.serve(i);
                        })
                })?;
            }
            let session_thread = self.starts.start(0, cores, || {
                std::thread::Builder::new()
                    .name("team-0".to_owned())
                    .spawn_scoped(scope, move || {
                        placement.on_start(0);
                        session.run(&executor)
                    })
            })?;
            let joined = session_thread.join();
            Ok(joined.unwrap_or_else(|payload| std::panic::resume_unwind(payload)))
        })
    }
}

/// Tells the threads to exit when dropped, including during unwinding.
struct ShutDownOnDrop<'a>(&'a TeamBoard);

impl Drop for ShutDownOnDrop<'_> {
    fn drop(&mut self) {
        self.0.shut_down();
    }
}

/// Opens each pass on the board.
///
/// Deliberately not `Sync`: a kernel (which must be `Sync`) therefore cannot capture the
/// executor and start a nested pass from a worker, which the board refuses.
struct TeamExecutor<'a> {
    board: &'a TeamBoard,
    /// The team's threads, the session's included.
    threads: usize,
    not_sync: PhantomData<Cell<()>>,
}

/// One block of a pass: claimed by exactly one thread, which moves the chunk out.
struct Block<O> {
    claimed: AtomicBool,
    chunk: Mutex<Option<(usize, O)>>,
}

impl<O> Block<O> {
    /// The block's chunk, for the one thread that claims it first.
    fn claim(&self) -> Option<(usize, O)> {
        // A plain read first: a block already taken costs no write to its cache line.
        if self.claimed.load(Ordering::Relaxed) || self.claimed.swap(true, Ordering::AcqRel) {
            return None;
        }
        self.chunk
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .take()
    }
}

impl Executor for TeamExecutor<'_> {
    fn for_each_chunk<O, F>(&self, out: O, kernel: F) -> Result<(), KernelPanic>
    where
        O: Split,
        F: Fn(usize, O) + Sync,
    {
        if out.is_empty() {
            return Ok(());
        }
        let blocks: Vec<Block<O>> = balanced_chunks(out, self.threads)
            .into_iter()
            .map(|chunk| Block {
                claimed: AtomicBool::new(false),
                chunk: Mutex::new(Some(chunk)),
            })
            .collect();
        let first_panic: OnceLock<KernelPanic> = OnceLock::new();

        // Run by thread `me`: its own block first, then any block nobody has started, the
        // next ones first. A panicking kernel is caught here; the first panic is kept.
        let job = |me: usize| {
            let n = blocks.len();
            for k in 0..n {
                if let Some((first, chunk)) = blocks[(me + k) % n].claim()
                    && let Err(p) = panic::catch(|| kernel(first, chunk))
                {
                    let _ = first_panic.set(p); // a later panic: the first one is kept
                }
            }
        };
        let escaped = self.board.run(&job);

        match first_panic.into_inner() {
            Some(p) => Err(p),
            None => escaped,
        }
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
    fn with_every_thread_present_each_pass_gives_each_thread_one_block() {
        // Each call sleeps 1 ms, far longer than a thread takes to join the pass.
        let passes = thread_ids_per_pass::<Team>(3, 1, 30, 5);
        assert!(passes.iter().all(|pass| pass.len() == 3), "{passes:?}");
        let all: Vec<_> = passes.concat();
        assert!((2..=3).contains(&distinct(&all)), "{passes:?}");
        assert!(!all.contains(&std::thread::current().id()));
    }

    #[test]
    fn a_thread_the_system_refuses_fails_the_run_before_the_session_starts() {
        for (refuse, message) in [
            (2, "could not start worker thread 3 of 4"),
            (0, "could not start worker thread 1 of 4"),
        ] {
            let strategy = Team {
                cores: 4,
                placement: Placement::OS,
                starts: ThreadStarts {
                    refuse: Some(refuse),
                },
            };
            let counted = run_counting(strategy, 100, 5);
            let err = counted.run.expect_err("the refused thread is an error");
            assert_eq!(err.to_string(), message);
            assert_eq!((counted.started, counted.ended), (0, 0), "{message}");
        }
    }
}
