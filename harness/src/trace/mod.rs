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
//! `timeline.png` (`sph_report::plot::timeline`, a Gantt chart) and `stats.csv` ([`stats`]),
//! all written by pure exporters to `impl Write`; [`files`] is the directory's schema: the
//! files' names, `meta.json` and the rows of `stats.csv`, written and read through the same
//! types.

pub mod chrome;
pub mod executor;
pub mod files;
pub mod recorder;
pub mod session;
pub mod size;
pub mod stats;

pub use executor::TracingExecutor;
pub use files::TraceConfig;
pub use recorder::{KernelEvent, Recorder, SerialEvent, SerialWork, ThreadInfo, Trace};
pub use session::{TracedRun, run_traced, run_untraced};
