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
//! [`rayon_chunks`], [`crossbeam_pool`] and [`std_static`]; each module's documentation says
//! how it schedules a pass and what that costs. The rayon strategies own a pool of exactly
//! `cores` threads built in [`Strategy::build`]; `crossbeam-pool` starts its `cores` threads
//! once per run; `std-static` starts threads on every pass.
//!
//! All of this is safe Rust except one small private module, `erased_job`, which lets
//! `crossbeam-pool`'s long-lived threads call a kernel borrowed for one pass (its safe API
//! returns only once every worker is done with the kernel; see the `// SAFETY:` notes there).

pub mod crossbeam_pool;
mod degrade;
mod erased_job;
mod panic;
pub mod rayon_chunks;
pub mod rayon_iter;
mod rayon_pool;
pub mod rayon_spawn;
mod registry;
pub mod seq;
mod spin_wait;
mod split;
pub mod std_static;
#[cfg(test)]
mod testing;
mod thread_start;

pub use panic::KernelPanic;
pub use registry::{StrategyName, UnknownStrategy, run};
pub use split::{Split, balanced_chunks};

/// How many threads and chunks a strategy should use.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Config {
    /// Worker threads (>= 1). Strategies that run on the calling thread ignore it.
    pub cores: usize,
    /// Requested number of chunks per pass (>= 1); the strategy makes `min(chunks, len)`
    /// balanced chunks. Strategies without a chunks parameter ignore it.
    pub chunks: usize,
}

/// Static facts about a strategy, shown by `bench-sph list` and used by the study runner.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Info {
    /// The name used on the command line, in CSV files and in plots.
    pub name: &'static str,
    /// One line saying how the strategy schedules work.
    pub description: &'static str,
    /// Whether `--chunks` changes what the strategy does.
    pub uses_chunks: bool,
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
    /// Name, description and whether chunks apply.
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
