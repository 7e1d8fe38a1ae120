//! `chili`: `min(chunks, len)` balanced chunks, run by recursive `join`s on a
//! [chili](https://github.com/dragostis/chili) pool (heartbeat scheduling, a Rust port of
//! Spice).
//!
//! **Scheduling.** [`Strategy::build`] builds a `chili::ThreadPool` of `cores` threads: chili
//! starts `cores − 1` workers, and the thread that holds a `chili::Scope` of the pool is the
//! last one. [`Strategy::run`] starts one thread for the session (worker 0, placed as
//! `--pin` asks; the calling thread only waits for it, as with the other strategies), which
//! takes that scope and computes too, and `cores − 1` worker threads help it. Each pass cuts the output into `min(chunks, len)` balanced chunks and
//! halves the chunk list recursively with `Scope::join` down to single chunks, so the kernel is
//! called exactly once per chunk (every chunk sits in one slot of the list, which exactly one
//! leaf of the recursion empties). Unlike rayon, a `join` offers nothing to other threads: it
//! runs its second half at once and keeps the first on the thread's private queue (deep in the
//! tree most joins are plain calls). Only once the thread's heartbeat has fired (every 100 µs,
//! chili's default) does the thread, when it next starts a deferred half, move its oldest
//! (largest) pending half to a shared list and wake a sleeping worker to take it. Work
//! therefore spreads by at most one half per heartbeat and per busy thread; a pass that is over
//! within a heartbeat or two may run on fewer threads than `cores`.
//!
//! **Cost.** No thread start-up per pass (the pool is built once, outside timing); per pass a
//! vector of chunks and one `join` per chunk, nearly all of them plain function calls that
//! touch no other thread; a shared half costs a lock and waking a sleeping worker (tens of
//! microseconds, more on a virtual machine), and its joiner may wait for it at the end. While
//! the session holds its scope, chili's heartbeat thread (a thread beyond the `cores`, which
//! computes nothing) wakes every `100 µs / cores` to set the flags: a steady, small CPU cost
//! for the whole run, even between passes.
//!
//! **Placement.** chili starts its workers itself and has no thread-start hook, so a worker is
//! placed when it first runs a chunk of the run, before its kernel call: the `cores − 1`
//! workers get indices 1, 2, … in the order they first compute (a worker that never computes
//! in a run is never placed, and needs no place). The session's thread, which computes too, is
//! worker 0, placed when it starts. The heartbeat thread is never placed. The
//! first pass of a run thus also pays for placing the workers.
//!
//! **Panics.** A kernel panic is caught per chunk, inside the leaf of the recursion, so that no
//! unwinding ever crosses a chili `join` (chili is not built to unwind out of a join whose
//! other half another thread may be running). The first one is returned as [`KernelPanic`]
//! once every chunk of the pass has run, and the pool serves later passes.
//!
//! **Thread limits.** chili panics when the operating system refuses one of its threads;
//! [`Strategy::build`] catches that panic and fails with [`BuildError::Pool`], but the workers
//! chili had already started stay blocked for the rest of the process (chili cannot stop
//! them).

use std::cell::{Cell, RefCell};
use std::num::NonZero;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Duration;

use chili::Scope;

use crate::panic::FirstPanic;
use crate::{
    BuildError, Config, Executor, Info, KernelPanic, Placement, Session, Split, Strategy,
    balanced_chunks, panic,
};

/// How often a busy thread offers work to the others: chili's (and Spice's) default.
const HEARTBEAT: Duration = Duration::from_micros(100);

/// Balanced chunks joined recursively on a chili pool of `cores` threads (the session's
/// included).
#[derive(Debug)]
pub struct ChiliJoin {
    pool: chili::ThreadPool,
    cores: usize,
    chunks: usize,
    placement: Placement,
}

impl Strategy for ChiliJoin {
    const INFO: Info = Info {
        name: "chili",
        description: "a chili pool of --cores threads, the session's included (heartbeat \
                      scheduling); each pass joins halves of the min(--chunks, N) chunk list \
                      recursively, one kernel call per chunk; --pin places a worker when it \
                      first runs a chunk (chili has no thread-start hook)",
        calls: crate::Calls::Chunks,
    };

    fn build(config: &Config) -> Result<Self, BuildError> {
        config.validate()?;
        Ok(ChiliJoin {
            pool: build_pool(config.cores)?,
            cores: config.cores,
            chunks: config.chunks,
            placement: config.placement,
        })
    }

    /// Runs `session` on a thread of its own (worker 0), holding a scope of the pool; the
    /// calling thread waits for it.
    ///
    /// # Panics
    /// Re-raises a panic of `session` itself (the pool is left as it was).
    fn run<S: Session>(&self, session: S) -> Result<S::Output, BuildError> {
        let (pool, placement) = (&self.pool, self.placement);
        let (threads, chunks) = (self.cores, self.chunks);
        std::thread::scope(|scope| {
            let session_thread = std::thread::Builder::new()
                .name("chili-0".to_owned())
                .spawn_scoped(scope, move || {
                    placement.on_start(0);
                    // Created on this thread, which it counts as placed.
                    let placer = LazyPlacement::new(placement);
                    let exec = ChiliExecutor {
                        scope: RefCell::new(pool.scope()),
                        threads,
                        chunks,
                        placer,
                    };
                    session.run(&exec)
                })
                .map_err(|source| BuildError::ThreadStart {
                    thread: 1,
                    threads,
                    source,
                })?;
            let joined = session_thread.join();
            Ok(joined.unwrap_or_else(|payload| std::panic::resume_unwind(payload)))
        })
    }
}

/// A chili pool of `cores` threads, the scope holder's included.
fn build_pool(cores: usize) -> Result<chili::ThreadPool, BuildError> {
    let thread_count = NonZero::new(cores).ok_or(BuildError::ZeroCores)?;
    // chili panics if a thread cannot be started: see the module's **Thread limits.**
    panic::catch(|| {
        chili::ThreadPool::with_config(chili::Config {
            thread_count: Some(thread_count),
            heartbeat_interval: HEARTBEAT,
        })
    })
    .map_err(|p| BuildError::Pool(p.message))
}

/// Runs each pass's join tree on the session's scope.
///
/// Not `Sync` (it holds a `RefCell`): a kernel (which must be `Sync`) therefore cannot capture
/// the executor, so the scope is never borrowed twice.
struct ChiliExecutor<'p> {
    scope: RefCell<Scope<'p>>,
    threads: usize,
    chunks: usize,
    placer: LazyPlacement,
}

impl Executor for ChiliExecutor<'_> {
    fn for_each_chunk<O, F>(&self, out: O, kernel: F) -> Result<(), KernelPanic>
    where
        O: Split,
        F: Fn(usize, O) + Sync,
    {
        if out.is_empty() {
            return Ok(());
        }
        // Every chunk in its own slot (the collect can reuse the vector: `Option` of a chunk
        // is no larger than the chunk).
        let mut slots: Vec<Option<(usize, O)>> = balanced_chunks(out, self.chunks)
            .into_iter()
            .map(Some)
            .collect();
        let pass = Pass {
            kernel: &kernel,
            placer: &self.placer,
            panics: FirstPanic::default(),
        };
        join_chunks(&mut self.scope.borrow_mut(), &mut slots, &pass);
        pass.panics.or(Ok(()))
    }

    fn threads(&self) -> usize {
        self.threads
    }
}

/// What every leaf of one pass shares.
struct Pass<'a, F> {
    kernel: &'a F,
    placer: &'a LazyPlacement,
    /// The first kernel panic of the pass; later ones are dropped.
    panics: FirstPanic,
}

impl<F> Pass<'_, F> {
    /// Places the current thread if it has not been yet, then calls the kernel on `chunk`,
    /// keeping its panic.
    fn call<O>(&self, first: usize, chunk: O)
    where
        F: Fn(usize, O),
    {
        self.panics.catch(|| {
            self.placer.place_current_thread();
            (self.kernel)(first, chunk);
        });
    }
}

/// Runs every chunk of `slots` (each taken out of its slot once) by halving the list with
/// `scope.join` down to single chunks.
fn join_chunks<O, F>(scope: &mut Scope<'_>, slots: &mut [Option<(usize, O)>], pass: &Pass<'_, F>)
where
    O: Split,
    F: Fn(usize, O) + Sync,
{
    match slots {
        [] => {}
        [slot] => {
            if let Some((first, chunk)) = slot.take() {
                pass.call(first, chunk);
            }
        }
        _ => {
            let (left, right) = slots.split_at_mut(slots.len() / 2);
            scope.join(
                |s| join_chunks(s, left, pass),
                |s| join_chunks(s, right, pass),
            );
        }
    }
}

/// Places each thread of a run (but the one that started it) when it first computes.
struct LazyPlacement {
    placement: Placement,
    /// This run's token, never 0 (the value of a thread that was never placed).
    run: usize,
    /// The index the next thread to be placed gets.
    next_index: AtomicUsize,
}

/// Runs started so far in this process: each run's token.
static RUNS: AtomicUsize = AtomicUsize::new(1);

thread_local! {
    /// The token of the last run that placed this thread (0: none).
    static PLACED_IN: Cell<usize> = const { Cell::new(0) };
}

impl LazyPlacement {
    /// A new run's placement; the calling thread (the session's, worker 0, placed when it
    /// started) counts as placed already.
    fn new(placement: Placement) -> LazyPlacement {
        let run = RUNS.fetch_add(1, Ordering::Relaxed);
        PLACED_IN.with(|p| p.set(run));
        LazyPlacement {
            placement,
            run,
            next_index: AtomicUsize::new(1),
        }
    }

    /// Runs the hook with the next index on the current thread, unless it has been placed in
    /// this run already. Nothing but a branch for [`Placement::OS`].
    fn place_current_thread(&self) {
        if self.placement.is_os() {
            return;
        }
        let placed = PLACED_IN.with(|p| p.replace(self.run)) == self.run;
        if !placed {
            let index = self.next_index.fetch_add(1, Ordering::Relaxed);
            self.placement.on_start(index);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing::{distinct, thread_ids_per_pass};
    use std::collections::{HashMap, HashSet};
    use std::sync::Mutex;
    use std::thread::ThreadId;

    #[test]
    fn passes_are_spread_over_more_than_one_thread() {
        let passes = thread_ids_per_pass::<ChiliJoin>(2, 16, 16, 1);
        assert!(distinct(&passes[0]) > 1, "{passes:?}");
    }

    #[test]
    fn at_most_cores_threads_compute_and_the_caller_is_not_one_of_them() {
        let passes = thread_ids_per_pass::<ChiliJoin>(3, 64, 64, 5);
        let all: Vec<_> = passes.concat();
        assert!(distinct(&all) <= 3, "{passes:?}");
        assert!(!all.contains(&std::thread::current().id()), "{passes:?}");
    }

    /// Every (index, thread) the hook of [`placed_run`] was called with.
    static PLACED: Mutex<Vec<(usize, ThreadId)>> = Mutex::new(Vec::new());

    /// Three passes of 16 chunks that sleep 1 ms each on 3 cores, placed by a hook that
    /// records its calls; returns the workers that computed (the session's thread excluded),
    /// each with whether it had been placed before every one of its kernel calls.
    fn placed_run() -> HashMap<ThreadId, bool> {
        static RECORD: fn(usize) = |index| {
            PLACED
                .lock()
                .unwrap()
                .push((index, std::thread::current().id()));
        };
        let config = Config::new(3, 16).placed(Placement::new(&RECORD, 3));
        let strategy = ChiliJoin::build(&config).expect("the pool builds");
        strategy.run(SleepyPasses).expect("the run starts")
    }

    struct SleepyPasses;

    impl Session for SleepyPasses {
        type Output = HashMap<ThreadId, bool>;

        fn run<E: Executor>(self, exec: &E) -> HashMap<ThreadId, bool> {
            let caller = std::thread::current().id();
            let workers = Mutex::new(HashMap::new());
            for _ in 0..3 {
                let mut out = [0u8; 16];
                exec.for_each_chunk(&mut out[..], |_, _| {
                    let me = std::thread::current().id();
                    let placed = PLACED.lock().unwrap().iter().any(|&(_, t)| t == me);
                    std::thread::sleep(Duration::from_millis(1));
                    if me != caller {
                        *workers.lock().unwrap().entry(me).or_insert(true) &= placed;
                    }
                })
                .expect("no kernel panics");
            }
            workers.into_inner().unwrap()
        }
    }

    #[test]
    fn a_worker_is_placed_once_with_its_own_index_before_its_first_chunk() {
        let workers = placed_run();
        let all = PLACED.lock().unwrap().clone();
        // Worker 0, the session's thread, is placed once, when it starts.
        assert_eq!(all.iter().filter(|&&(i, _)| i == 0).count(), 1, "{all:?}");
        let placed: Vec<_> = all.into_iter().filter(|&(i, _)| i != 0).collect();
        assert!(!workers.is_empty(), "the workers helped");
        assert!(workers.values().all(|&before| before), "{workers:?}");
        let placed_threads: HashSet<ThreadId> = placed.iter().map(|&(_, t)| t).collect();
        let computed: HashSet<ThreadId> = workers.keys().copied().collect();
        assert_eq!(placed_threads, computed, "{placed:?}");
        let mut indices: Vec<usize> = placed.iter().map(|&(i, _)| i).collect();
        indices.sort_unstable();
        let expected: Vec<usize> = (1..=placed.len()).collect();
        assert_eq!(indices, expected, "{placed:?}");
    }
}
