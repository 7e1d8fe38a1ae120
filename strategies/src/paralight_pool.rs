//! `paralight`: `min(chunks, len)` balanced chunks as a
//! [paralight](https://github.com/gendx/paralight) parallel iterator over a pool of `cores`
//! threads, with work-stealing ranges.
//!
//! **Scheduling.** [`Strategy::build`] builds a paralight `ThreadPool` of exactly `cores`
//! worker threads. The session runs on the calling thread, which computes nothing: for each
//! pass it cuts the output into `min(chunks, len)` balanced chunks, lends the chunk list to the
//! pool as one parallel iterator (`Vec::into_par_iter`, which hands every item, and so every
//! chunk, to exactly one call), and waits until every worker has finished. Each worker starts
//! on its own contiguous range of the chunk list (`cores` near-equal ranges) and takes one
//! chunk at a time from its front; a worker whose range is empty steals half of the largest
//! range left.
//!
//! **Why work stealing, not fixed ranges.** With `RangeStrategy::Fixed` each worker must work
//! through its own range whatever happens, so a worker that shares its core with another busy
//! process holds up every pass by the time it is descheduled. With
//! `RangeStrategy::WorkStealing` the other workers take the chunks it has not started; the
//! pass still waits for it to wake once (paralight's pass ends when *every* worker has checked
//! in), but no longer for its share of the work. Its cost, a compare-and-swap per chunk and a
//! scan of the ranges (plus a small allocation) when a worker's own range runs out, is small
//! beside a chunk.
//!
//! **Why paralight, not orx-parallel.** Both offer a parallel iterator over a list, and
//! paralight (which asks for Rust 1.81) builds here. paralight's pool has exactly the threads
//! it is asked for, kept for the pool's life, and the list is split by the range strategy
//! alone: the study's `--cores` and `--chunks` mean what they say. orx-parallel takes a thread
//! count as an upper bound, lowered by the machine's CPUs, an `ORX_NUM_THREADS` environment
//! variable and the input's length, and its runner groups items by a chunk-size heuristic of
//! its own, so `--cores 4` could silently run on fewer threads; it also brings about a dozen
//! crates of its own (concurrent bags, iterators, vectors).
//!
//! **Cost.** No thread start-up per pass (the pool is built once, outside timing); per pass a
//! vector of chunks, one lending round — the caller wakes every worker through a condition
//! variable, and the last worker to finish wakes the caller — and one compare-and-swap per
//! chunk. Nobody spins: between passes the workers sleep, so every pass pays for waking them
//! (tens of microseconds, more on a virtual machine).
//!
//! **Placement.** paralight's own pinning (`CpuPinningPolicy`) puts worker i on CPU i and
//! cannot run our hook, so the pool is built without it and [`Strategy::build`] runs one
//! placement pass instead: an iterator over `0..cores` in which item i calls the hook with
//! index i and then waits at a barrier for all `cores` items. Since a worker runs one item at a
//! time and none can finish before all have started, each of the `cores` workers runs exactly
//! one item: every worker is placed once, with a distinct index, before it computes anything.
//! Without a hook there is no placement pass.
//!
//! **Panics.** A kernel panic is caught per chunk, on the worker (a panic that escaped would
//! end that paralight worker for good, and every later pass would wait for it); the first one
//! is returned as [`KernelPanic`] once the pass has finished, and the pool serves later passes.
//!
//! **Thread limits.** paralight panics when the operating system refuses one of its threads;
//! [`Strategy::build`] catches that panic and fails with [`BuildError::Pool`], but the workers
//! paralight had already started stay asleep for the rest of the process.

use std::any::Any;
use std::cell::RefCell;
use std::panic::{AssertUnwindSafe, catch_unwind, resume_unwind};
use std::sync::{Barrier, Mutex, MutexGuard};

use paralight::prelude::{
    CpuPinningPolicy, ExactParallelSourceExt, IntoExactParallelSource, ParallelIteratorExt,
    RangeStrategy, ThreadCount, ThreadPool, ThreadPoolBuilder,
};

use crate::panic::FirstPanic;
use crate::{
    BuildError, Config, Executor, Info, KernelPanic, Placement, Session, Split, Strategy,
    balanced_chunks, panic,
};

/// Balanced chunks as a paralight parallel iterator over a pool of `cores` threads.
pub struct ParalightPool {
    /// Locked by a run for its whole session (a pass needs the pool mutably).
    pool: Mutex<ThreadPool>,
    cores: usize,
    chunks: usize,
}

impl std::fmt::Debug for ParalightPool {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ParalightPool")
            .field("cores", &self.cores)
            .field("chunks", &self.chunks)
            .finish_non_exhaustive()
    }
}

impl Strategy for ParalightPool {
    const INFO: Info = Info {
        name: "paralight",
        description: "a paralight pool of --cores threads (the steps' caller only waits); each \
                      pass's min(--chunks, N) chunks are a paralight parallel iterator with \
                      work-stealing ranges, one kernel call per chunk",
        calls: crate::Calls::Chunks,
    };

    fn build(config: &Config) -> Result<Self, BuildError> {
        config.validate()?;
        let mut pool = build_pool(config.cores)?;
        if !config.placement.is_os() {
            place_workers(&mut pool, config.cores, config.placement);
        }
        Ok(ParalightPool {
            pool: Mutex::new(pool),
            cores: config.cores,
            chunks: config.chunks,
        })
    }

    /// Runs `session` on the calling thread, which lends each pass to the pool.
    ///
    /// # Panics
    /// Re-raises a panic of `session` itself (the pool is left as it was).
    fn run<S: Session>(&self, session: S) -> Result<S::Output, BuildError> {
        let mut pool = self.lock_pool();
        let exec = ParalightExecutor {
            pool: RefCell::new(&mut pool),
            threads: self.cores,
            chunks: self.chunks,
        };
        Ok(session.run(&exec))
    }
}

impl ParalightPool {
    /// The pool, also after a session that panicked while holding it: a kernel panic never
    /// leaves a pass unfinished, so the pool is still sound.
    fn lock_pool(&self) -> MutexGuard<'_, ThreadPool> {
        self.pool.lock().unwrap_or_else(|e| e.into_inner())
    }
}

/// A paralight pool of exactly `cores` unpinned workers with work-stealing ranges.
fn build_pool(cores: usize) -> Result<ThreadPool, BuildError> {
    let num_threads = ThreadCount::try_from(cores).map_err(|_| BuildError::ZeroCores)?;
    // paralight panics if a thread cannot be started: see the module's **Thread limits.**
    panic::catch(|| {
        ThreadPoolBuilder {
            num_threads,
            range_strategy: RangeStrategy::WorkStealing,
            cpu_pinning: CpuPinningPolicy::No,
        }
        .build()
    })
    .map_err(|p| BuildError::Pool(p.message))
}

/// Calls `placement`'s hook once on each of the pool's `cores` workers, with distinct indices
/// (see the module's **Placement.**).
///
/// # Panics
/// Re-raises the hook's first panic, once every worker is past the barrier.
fn place_workers(pool: &mut ThreadPool, cores: usize, placement: Placement) {
    let all_started = Barrier::new(cores);
    let first_panic: Mutex<Option<Box<dyn Any + Send>>> = Mutex::new(None);
    (0..cores)
        .into_par_iter()
        .with_thread_pool(pool)
        .for_each(|index| {
            let placed = catch_unwind(AssertUnwindSafe(|| placement.on_start(index)));
            // Reached even if the hook panicked: the other workers wait here.
            all_started.wait();
            if let Err(payload) = placed {
                let mut first = first_panic.lock().unwrap_or_else(|e| e.into_inner());
                first.get_or_insert(payload);
            }
        });
    let first = first_panic.into_inner().unwrap_or_else(|e| e.into_inner());
    if let Some(payload) = first {
        resume_unwind(payload);
    }
}

/// Lends each pass to the pool.
///
/// Not `Sync` (it holds a `RefCell`): a kernel (which must be `Sync`) therefore cannot capture
/// the executor and start a nested pass from a worker.
struct ParalightExecutor<'a> {
    pool: RefCell<&'a mut ThreadPool>,
    threads: usize,
    chunks: usize,
}

impl Executor for ParalightExecutor<'_> {
    fn for_each_chunk<O, F>(&self, out: O, kernel: F) -> Result<(), KernelPanic>
    where
        O: Split,
        F: Fn(usize, O) + Sync,
    {
        if out.is_empty() {
            return Ok(());
        }
        let chunks = balanced_chunks(out, self.chunks);
        let panics = FirstPanic::default();
        let mut pool = self.pool.borrow_mut();
        // Caught around the whole pass too: paralight itself may panic on the caller (e.g.
        // over 2^32 items), never on a worker.
        let escaped = panic::catch(|| {
            chunks
                .into_par_iter()
                .with_thread_pool(&mut **pool)
                .for_each(|(first, chunk)| panics.catch(|| kernel(first, chunk)));
        });
        panics.or(escaped)
    }

    fn threads(&self) -> usize {
        self.threads
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing::{distinct, thread_ids_per_pass};
    use std::collections::HashSet;
    use std::thread::ThreadId;

    #[test]
    fn passes_are_spread_over_more_than_one_thread() {
        let passes = thread_ids_per_pass::<ParalightPool>(2, 16, 16, 1);
        assert!(distinct(&passes[0]) > 1, "{passes:?}");
    }

    #[test]
    fn building_with_a_hook_places_every_worker_once_with_its_own_index() {
        static PLACED: Mutex<Vec<(usize, ThreadId)>> = Mutex::new(Vec::new());
        static RECORD: fn(usize) = |index| {
            PLACED
                .lock()
                .unwrap()
                .push((index, std::thread::current().id()));
        };
        let config = Config::new(3, 16).placed(Placement::new(&RECORD, 3));
        let strategy = ParalightPool::build(&config).expect("the pool builds");
        let placed = PLACED.lock().unwrap().clone();
        let mut indices: Vec<usize> = placed.iter().map(|&(i, _)| i).collect();
        indices.sort_unstable();
        assert_eq!(indices, [0, 1, 2], "{placed:?}");
        let threads: HashSet<ThreadId> = placed.iter().map(|&(_, t)| t).collect();
        assert_eq!(threads.len(), 3, "{placed:?}");
        assert!(!threads.contains(&std::thread::current().id()));
        // The threads that compute are the placed ones.
        let passes = strategy.run(ThreadsOfOnePass).expect("the run starts");
        assert!(passes.is_subset(&threads), "{passes:?} {placed:?}");
    }

    struct ThreadsOfOnePass;

    impl Session for ThreadsOfOnePass {
        type Output = HashSet<ThreadId>;

        fn run<E: Executor>(self, exec: &E) -> HashSet<ThreadId> {
            let threads = Mutex::new(HashSet::new());
            let mut out = [0u8; 16];
            exec.for_each_chunk(&mut out[..], |_, _| {
                std::thread::sleep(std::time::Duration::from_millis(1));
                threads.lock().unwrap().insert(std::thread::current().id());
            })
            .expect("no kernel panics");
            threads.into_inner().unwrap()
        }
    }

    #[test]
    fn the_same_workers_serve_every_pass_and_the_caller_computes_nothing() {
        let passes = thread_ids_per_pass::<ParalightPool>(3, 64, 64, 10);
        let all: Vec<_> = passes.concat();
        assert!(distinct(&all) <= 3, "{passes:?}");
        assert!(!all.contains(&std::thread::current().id()));
    }
}
