//! bench-sph: a 2D SPH dam-break solver (Müller 2003, as ported by the seed paper, and a
//! weakly compressible SPH validated against experiment) behind interchangeable parallel
//! strategies, and the tools to measure them.
//!
//! - [`sph`]: the pure physics (constants, state, neighbour search, per-particle passes);
//! - [`simd`]: the instruction sets the neighbour tests run on, picked at start-up;
//! - [`solver`]: one step as the model's passes run by a strategy's executor;
//! - [`scene`]: initial dam-break states; [`io`]: CSV in and out;
//! - [`validate`]: the `wcsph` dam break against Martin & Moyce (1952) (`bench-sph validate`);
//! - [`run`]: a run in one strategy session: the step loop timed (in segments, with an
//!   observer between them), warm-up, fault injection; [`clock`], [`checksum`]: what a run
//!   reports; [`contention`]: what the rest of the machine did meanwhile;
//! - [`topology`]: the cores, SMT siblings, sockets, caches and frequency policy of the CPUs
//!   the process may use (sysfs), and the orders worker threads would be pinned in;
//! - [`limits`]: the documented range of every numeric option;
//! - [`placement`]: `--pin`, which logical CPUs a run's threads run on;
//! - [`output`]: files written whole or not at all, output directories, a closable stdout;
//! - [`plot`]: the bundled font shared by charts and animations;
//! - [`render`]: animations of the dam break (GIF or PNG frames); `viewer` (cargo feature
//!   `viewer`): the same, live in a window;
//! - [`sweep`]: the cores × chunks study (`bench-sph sweep`); [`results`]: the schema of its
//!   results directory, which the sweep writes and the report reads;
//! - [`merge`]: one results directory from the shards of a sweep (`bench-sph merge`);
//! - [`report`]: charts and REPORT.md from results directories (`bench-sph report`);
//! - [`trace`]: per-worker timelines of a few steps (`bench-sph trace`);
//! - [`cli`]: the `bench-sph` command line.

pub use sph_solver::{checksum, scene, simd, solver, sph, with_lanes};

pub mod cli;
pub mod clock;
pub mod contention;
pub mod io;
pub mod limits;
pub mod merge;
pub mod output;
pub mod placement;
pub mod plot;
pub mod render;
pub mod report;
pub mod results;
pub mod run;
pub mod signals;
pub mod sweep;
pub mod topology;
pub mod trace;
pub mod validate;
#[cfg(feature = "viewer")]
pub mod viewer;
