//! `bench-sph trace`: where each worker spends its time — the analogue of the seed paper's
//! Threadscope timelines and its runtime's `SPARKS:` statistics, for every strategy.
//!
//! A traced run ([`session::run_traced`]) drives the same step loop as an untraced one, with
//! hooks that run each phase on the strategy's own executor wrapped in a [`TracingExecutor`],
//! which reads a monotonic clock around every kernel call and records one [`KernelEvent`] per
//! call — per chunk for the chunked strategies, per task for `rayon-spawn`, per leaf for
//! `rayon-iter`,
//! per block for `std-static` — never per particle. The wrapper changes neither the chunks
//! nor the threads, and untraced runs never see it, so they pay nothing. The calling thread's
//! serial work between passes (grid rebuild, divergence check) is recorded too.
//!
//! Before recording, a few unrecorded warm-up steps wake the pool's threads ([`session`]);
//! before anything runs, the trace's size is estimated and capped ([`size::MAX_EVENTS`]).
//!
//! The [`Trace`] then becomes `trace.json` ([`chrome`], for Perfetto or `chrome://tracing`),
//! `timeline.png` (`sph_report::plot::timeline`, a Gantt chart) and `stats.csv` ([`stats`]), all written by
//! pure exporters to `impl Write`; [`files`] names them and recognises a trace directory.

pub mod chrome;
pub mod executor;
pub mod files;
pub mod recorder;
pub mod session;
pub mod size;
pub mod stats;

use serde::Serialize;

use sph_solver::sph::neighbors::NeighborMode;
use sph_solver::sph::params::Preset;

pub use executor::TracingExecutor;
pub use recorder::{KernelEvent, Recorder, SerialEvent, SerialWork, ThreadInfo, Trace};
pub use session::{TracedRun, run_traced, run_untraced};

/// What was traced: shown in titles and written to `trace.json`'s `otherData` and `meta.json`.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct TraceConfig {
    /// The strategy's name.
    pub strategy: String,
    /// Worker threads (1 for `seq`).
    pub cores: usize,
    /// Requested chunks per pass, for strategies that use chunks.
    pub chunks: Option<usize>,
    /// Particles.
    pub n: usize,
    /// Steps traced.
    pub steps: usize,
    /// Constants.
    pub preset: Preset,
    /// Neighbour search.
    pub neighbors: NeighborMode,
    /// Seed of the initial jitter (none with an init file).
    pub seed: Option<u64>,
    /// The init file the state came from, if any.
    pub init: Option<String>,
}

impl TraceConfig {
    /// One line: `rayon-chunks, 2 cores, 45 chunks, N = 1000 (seed, all-pairs)`.
    pub fn title(&self) -> String {
        let cores = if self.cores == 1 { "core" } else { "cores" };
        let chunks = self
            .chunks
            .map_or_else(String::new, |c| format!(", {c} chunks"));
        format!(
            "{}, {} {cores}{chunks}, N = {} ({}, {})",
            self.strategy,
            self.cores,
            self.n,
            self.preset.as_str(),
            self.neighbors.as_str()
        )
    }
}
