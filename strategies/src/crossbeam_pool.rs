//! `crossbeam-pool`: a hand-rolled pool of `cores` threads that lives for the whole run, with
//! chunks handed out dynamically.
//!
//! **Scheduling.** [`Strategy::run`] starts exactly `cores` worker threads in a
//! `crossbeam::scope` and keeps them for the whole session; the session itself runs on the
//! first of them (the calling thread only waits for it). For each pass that thread cuts the
//! output into `min(chunks, len)` balanced chunks, publishes one job on a job board, works on
//! the job itself, and waits until every other worker has finished it. Each worker pulls chunk
//! indices from a shared atomic counter until the chunks run out — so fast workers take more
//! chunks — and takes the chunk out of its slot (a `Mutex<Option<_>>` per chunk, locked once,
//! uncontended).
//!
//! **Cost.** No thread start-up per pass; per pass one publication and one completion
//! rendezvous. Waiting threads spin for up to 200 µs before they sleep on a condition
//! variable, so back-to-back passes need no wake-up (waking a sleeping thread costs tens of
//! microseconds, far more on a virtual machine); the spinning shows up as CPU time. Per chunk
//! one atomic `fetch_add` and one uncontended lock. Nothing per element.
//!
//! **Panics.** A kernel panic is caught per chunk; the first one is returned as
//! [`KernelPanic`] once the pass has finished, and the workers keep serving later passes.
//!
//! **Shut-down.** When the session returns — or unwinds — a guard tells the workers to exit,
//! so the scope always joins them.
//!
//! Handing a job borrowed for one pass to threads that outlive it needs lifetime erasure;
//! that `unsafe` is confined to the private module `erased_job`, whose safe API returns only
//! after every worker is done with the job.

use std::cell::Cell;
use std::marker::PhantomData;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Mutex, PoisonError};

use crate::erased_job::JobBoard;
use crate::{
    BuildError, Config, Executor, Info, KernelPanic, Session, Split, Strategy, balanced_chunks,
    panic,
};

/// A pool of `cores` long-lived crossbeam scoped threads pulling chunks dynamically.
#[derive(Debug, Clone, Copy)]
pub struct CrossbeamPool {
    cores: usize,
    chunks: usize,
}

impl Strategy for CrossbeamPool {
    const INFO: Info = Info {
        name: "crossbeam-pool",
        description: "a pool of --cores crossbeam threads kept for the whole run (the steps \
                      run on one of them); each pass's chunks are pulled dynamically from an \
                      atomic counter",
        uses_chunks: true,
    };

    fn build(config: &Config) -> Result<Self, BuildError> {
        config.validate()?;
        Ok(CrossbeamPool {
            cores: config.cores,
            chunks: config.chunks,
        })
    }

    /// Starts the workers, runs `session` on the first of them, then stops and joins the
    /// others.
    ///
    /// # Panics
    /// If the operating system refuses to start a worker thread, and re-raises a panic of
    /// `session` itself once the workers have been joined.
    fn run<S: Session>(&self, session: S) -> S::Output {
        let board = JobBoard::new(self.cores - 1);
        let executor = PoolExecutor {
            board: &board,
            chunks: self.chunks,
            not_sync: PhantomData,
        };
        let outcome = crossbeam::scope(|scope| {
            // Created before the first worker, so that every way out of this closure — a
            // return, a failed spawn, a panicking session — releases the workers first.
            let _stop = ShutDownOnDrop(&board);
            for i in 1..self.cores {
                scope
                    .builder()
                    .name(format!("crossbeam-pool-{i}"))
                    .spawn(|_| board.serve())
                    .expect("could not start a crossbeam-pool worker thread");
            }
            scope
                .builder()
                .name("crossbeam-pool-0".to_owned())
                .spawn(move |_| session.run(&executor))
                .expect("could not start a crossbeam-pool worker thread")
                .join()
        })
        // A serving thread cannot panic: `serve` catches whatever a job throws.
        .expect("a crossbeam-pool worker thread panicked");
        outcome.unwrap_or_else(|payload| std::panic::resume_unwind(payload))
    }
}

/// Tells the workers to exit when dropped, including during unwinding.
struct ShutDownOnDrop<'a>(&'a JobBoard);

impl Drop for ShutDownOnDrop<'_> {
    fn drop(&mut self) {
        self.0.shut_down();
    }
}

/// Publishes each pass on the board.
///
/// Deliberately not `Sync`: a kernel (which must be `Sync`) therefore cannot capture the
/// executor and start a nested pass from a worker, which would wait for itself forever.
struct PoolExecutor<'a> {
    board: &'a JobBoard,
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
        let slots: Vec<Mutex<Option<(usize, O)>>> = balanced_chunks(out, self.chunks)
            .into_iter()
            .map(|chunk| Mutex::new(Some(chunk)))
            .collect();
        let next = AtomicUsize::new(0);
        let first_panic: Mutex<Option<KernelPanic>> = Mutex::new(None);

        // Run by every worker. No lock is held while a kernel runs, so a panicking kernel
        // poisons nothing (poisoning is ignored all the same).
        let job = || {
            loop {
                // Relaxed is enough: the counter only has to hand each index out once; the
                // chunk itself travels through its slot's mutex.
                let i = next.fetch_add(1, Ordering::Relaxed);
                let Some(slot) = slots.get(i) else { break };
                let taken = slot.lock().unwrap_or_else(PoisonError::into_inner).take();
                let Some((first, chunk)) = taken else {
                    unreachable!("chunk {i} handed out twice")
                };
                if let Err(p) = panic::catch(|| kernel(first, chunk)) {
                    first_panic
                        .lock()
                        .unwrap_or_else(PoisonError::into_inner)
                        .get_or_insert(p);
                }
            }
        };
        let escaped = self.board.run(&job);

        let caught = first_panic
            .into_inner()
            .unwrap_or_else(PoisonError::into_inner);
        match caught {
            Some(p) => Err(p),
            None => escaped,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing::{distinct, thread_ids_per_pass};

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
}
