//! Interchangeable ways to run one data-parallel pass on a number of threads.
//!
//! This crate knows nothing about SPH. A pass is an output — one mutable slice, or a tuple of
//! equal-length slices cut in lockstep (see [`Split`]) — and a kernel
//! `Fn(first_index, chunk)`. A strategy decides only which thread fills which disjoint chunk:
//! it must call the kernel exactly once per chunk of a partition of the output, and never
//! touch the data itself. Because every element is written by exactly one kernel call, and a
//! kernel's result for an element does not depend on the chunking, every strategy produces
//! the same bits as [`seq`].
//!
//! A run has two phases:
//! 1. [`Strategy::build`] creates long-lived resources (thread pools) — outside any timing;
//! 2. [`Strategy::run`] hands a [`Session`] an [`Executor`], on which the session calls
//!    [`Executor::for_each_chunk`] once per pass, as often as it likes.
//!
//! Strategies are chosen by name through the [registry](StrategyName); adding one is one new
//! file plus one registry line. They are [`seq`], [`rayon_iter`], [`rayon_spawn`],
//! [`rayon_chunks`], [`crossbeam_pool`], [`std_static`], [`team`], [`chili_join`] and
//! [`paralight_pool`]; each module's documentation says how it schedules a pass and what that
//! costs. The rayon strategies and `paralight` own a pool of exactly `cores` threads built in
//! [`Strategy::build`], `chili` one of `cores − 1` threads that the calling thread joins;
//! `crossbeam-pool` and `team` start their `cores` threads once per run; `std-static` starts
//! threads on every pass.
//!
//! All of this is safe Rust except one small private module, `erased_job`, which lets
//! `crossbeam-pool`'s and `team`'s long-lived threads call a kernel borrowed for one pass (its
//! safe API returns only once every worker is done with the kernel; see the `// SAFETY:` notes
//! there).

pub mod chili_join;
pub mod crossbeam_pool;
mod erased_job;
mod panic;
pub mod paralight_pool;
pub mod placement;
pub mod rayon_chunks;
pub mod rayon_iter;
mod rayon_pool;
pub mod rayon_spawn;
mod registry;
pub mod seq;
mod spin_wait;
mod split;
pub mod std_static;
pub mod team;
#[cfg(test)]
mod testing;
mod thread_start;
pub mod wake;
mod whereabouts;

pub use panic::KernelPanic;
pub use placement::Placement;
pub use registry::{StrategyName, UnknownStrategy, run};
pub use split::{Split, balanced_chunks};
pub use wake::{Woken, rouse, wake};

/// How many threads and chunks a strategy should use.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Config {
    /// Worker threads (>= 1). Strategies that run on the calling thread ignore it.
    pub cores: usize,
    /// Requested number of chunks per pass (>= 1); the strategy makes `min(chunks, len)`
    /// balanced chunks. Strategies without a chunks parameter ignore it.
    pub chunks: usize,
    /// What each worker thread does first (see [`placement`]); [`Placement::OS`] by default.
    pub placement: Placement,
}

/// Static facts about a strategy, shown by `bench-sph list` and used by the study runner, the
/// trace and the tests: everything above this crate asks [`Info`] rather than matching on a
/// strategy's name, so that a new strategy is one file plus one registry line.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Info {
    /// The name used on the command line, in CSV files and in plots.
    pub name: &'static str,
    /// One line saying how the strategy schedules work.
    pub description: &'static str,
    /// How the strategy cuts a pass into kernel calls.
    pub calls: Calls,
}

/// How a strategy cuts a pass over `len` elements into kernel calls.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Calls {
    /// One call for the whole output, on the calling thread: the strategy uses one core
    /// whatever [`Config::cores`] says.
    Whole,
    /// `min(chunks, len)` balanced chunks: the only kind that [`Config::chunks`] changes.
    Chunks,
    /// `min(cores, len)` contiguous blocks, one per thread.
    Blocks,
    /// One call per element.
    Elements,
    /// The runtime decides, between one call and one per element: no exact count.
    Adaptive,
}

impl Info {
    /// Whether `--chunks` changes what the strategy does.
    pub fn uses_chunks(&self) -> bool {
        self.calls == Calls::Chunks
    }

    /// The chunks a run of the strategy uses when `requested` are asked for: `None` for a
    /// strategy that ignores them (as reports show it: `n/a`, an empty CSV field).
    pub fn effective_chunks(&self, requested: usize) -> Option<usize> {
        self.uses_chunks().then_some(requested)
    }

    /// The worker threads a run of the strategy uses when `requested` are asked for: 1 for a
    /// strategy that runs each pass as one call on the calling thread, `requested` otherwise.
    pub fn effective_cores(&self, requested: usize) -> usize {
        match self.calls {
            Calls::Whole => 1,
            _ => requested,
        }
    }

    /// The kernel calls one pass over `len` elements makes with `config`, where the strategy
    /// promises an exact number (every [`Calls`] but [`Calls::Adaptive`]).
    pub fn kernel_calls(&self, len: usize, config: &Config) -> Option<usize> {
        match self.calls {
            Calls::Whole => Some(1.min(len)),
            Calls::Chunks => Some(config.chunks.min(len)),
            Calls::Blocks => Some(config.cores.min(len)),
            Calls::Elements => Some(len),
            Calls::Adaptive => None,
        }
    }
}

/// Why a strategy could not be built, or could not start the threads of a run.
#[derive(Debug, thiserror::Error)]
pub enum BuildError {
    /// `cores` was zero.
    #[error("cores must be at least 1")]
    ZeroCores,
    /// `chunks` was zero.
    #[error("chunks must be at least 1")]
    ZeroChunks,
    /// The operating system refused to start a rayon pool's threads.
    #[error("could not start the thread pool: {0}")]
    Pool(String),
    /// The operating system refused to start one of the threads a run (or, for `std-static`,
    /// a pass) needs; the threads already started have been stopped and joined.
    #[error("could not start worker thread {thread} of {threads}")]
    ThreadStart {
        /// Which thread, 1-based.
        thread: usize,
        /// How many the run or pass needed.
        threads: usize,
        /// The operating system's reason (e.g. `EAGAIN` under a process or thread limit).
        source: std::io::Error,
    },
}

impl Config {
    /// `cores` threads and `chunks` chunks, placed by the operating system.
    pub const fn new(cores: usize, chunks: usize) -> Config {
        Config {
            cores,
            chunks,
            placement: Placement::OS,
        }
    }

    /// The same, with its worker threads placed by `placement`.
    pub const fn placed(self, placement: Placement) -> Config {
        Config { placement, ..self }
    }

    /// Checks the numbers a strategy relies on.
    pub fn validate(&self) -> Result<(), BuildError> {
        if self.cores == 0 {
            return Err(BuildError::ZeroCores);
        }
        if self.chunks == 0 {
            return Err(BuildError::ZeroChunks);
        }
        Ok(())
    }
}

/// Runs passes for a [`Session`].
pub trait Executor {
    /// Calls `kernel(first_index, chunk)` exactly once for every chunk of a partition of `out`
    /// into disjoint, contiguous chunks, and returns when all calls have finished.
    ///
    /// A panic inside a kernel is caught and returned as [`KernelPanic`]; the outputs are then
    /// partly written and must be discarded. Never hangs because a kernel panicked.
    fn for_each_chunk<O, F>(&self, out: O, kernel: F) -> Result<(), KernelPanic>
    where
        O: Split,
        F: Fn(usize, O) + Sync;

    /// How many threads the executor's passes may run on at once: 1 when every pass runs on
    /// the calling thread. What a kernel computes must not depend on it; a caller may use it
    /// to choose between ways of computing the same thing (the grid's counting sort runs in
    /// bands only with more than one thread).
    fn threads(&self) -> usize;
}

/// The body of a run: everything that happens while a strategy's threads exist.
///
/// It is a trait rather than a closure because its `run` is generic over the executor, so that
/// every pass is statically dispatched. It is `Send` because a strategy may run it on one of
/// its own threads.
pub trait Session: Send {
    /// What the run produces.
    type Output: Send;

    /// Runs the body with `exec`.
    fn run<E: Executor>(self, exec: &E) -> Self::Output;
}

/// A way of scheduling passes on threads.
pub trait Strategy: Sized {
    /// Name, description and how a pass is cut into kernel calls.
    const INFO: Info;

    /// Creates the strategy's long-lived resources for `config` (e.g. a thread pool with
    /// exactly `config.cores` threads). Not part of any timed region.
    fn build(config: &Config) -> Result<Self, BuildError>;

    /// Runs `session`, giving it an executor backed by this strategy's threads.
    ///
    /// Fails with [`BuildError::ThreadStart`] if the operating system refuses a thread the run
    /// needs — before the session starts, or (`std-static`) during a pass, whose error then
    /// ends the session; the session's output is discarded. No thread is left behind.
    fn run<S: Session>(&self, session: S) -> Result<S::Output, BuildError>;
}

#[cfg(test)]
mod tests {
    use super::*;

    fn info(calls: Calls) -> Info {
        Info {
            name: "x",
            description: "x",
            calls,
        }
    }

    #[test]
    fn each_kind_of_strategy_promises_its_kernel_calls_per_pass() {
        let config = Config::new(3, 7);
        let calls = |kind, len| info(kind).kernel_calls(len, &config);
        assert_eq!(calls(Calls::Whole, 100), Some(1));
        assert_eq!(calls(Calls::Whole, 0), Some(0));
        assert_eq!(calls(Calls::Chunks, 100), Some(7));
        assert_eq!(calls(Calls::Chunks, 5), Some(5));
        assert_eq!(calls(Calls::Blocks, 100), Some(3));
        assert_eq!(calls(Calls::Blocks, 2), Some(2));
        assert_eq!(calls(Calls::Elements, 100), Some(100));
        assert_eq!(calls(Calls::Adaptive, 100), None);
    }

    #[test]
    fn only_a_whole_pass_strategy_runs_on_one_core_and_only_a_chunked_one_uses_chunks() {
        for kind in [
            Calls::Chunks,
            Calls::Blocks,
            Calls::Elements,
            Calls::Adaptive,
        ] {
            assert_eq!(info(kind).effective_cores(4), 4, "{kind:?}");
            let chunked = kind == Calls::Chunks;
            assert_eq!(info(kind).uses_chunks(), chunked, "{kind:?}");
            assert_eq!(
                info(kind).effective_chunks(9),
                chunked.then_some(9),
                "{kind:?}"
            );
        }
        assert_eq!(info(Calls::Whole).effective_cores(4), 1);
        assert_eq!(info(Calls::Whole).effective_chunks(9), None);
        assert_eq!(StrategyName::Seq.info().calls, Calls::Whole);
    }
}
