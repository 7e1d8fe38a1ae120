//! The harness of bench-sph: what measures the solver and what keeps the measurements.
//!
//! It sits between the physics (`sph-solver`, which it runs) and the report (`sph-report`,
//! which reads what it writes), and names neither the report nor the command line.
//!
//! - [`run`]: a run in one strategy session: the step loop timed (in segments, with an
//!   observer between them), warm-up, fault injection; [`clock`]: what a run reports;
//!   [`contention`]: what the rest of the machine did meanwhile;
//! - [`topology`]: the cores, SMT siblings, sockets, caches and frequency policy of the CPUs
//!   the process may use (sysfs), and the orders worker threads would be pinned in;
//! - [`placement`]: `--pin`, which logical CPUs a run's threads run on;
//! - [`limits`]: the documented range of every numeric option;
//! - [`io`]: where a command's output file goes and how files are read back (capped), over the
//!   solver's state CSV;
//! - [`output`]: files written whole or not at all, output directories, a closable stdout;
//!   [`signals`]: Ctrl-C as an orderly stop;
//! - [`sweep`]: the cores × chunks study (`bench-sph sweep`); [`results`]: the schema of its
//!   results directory, which the sweep writes and the report reads;
//! - [`merge`]: one results directory from the shards of a sweep (`bench-sph merge`);
//! - [`trace`]: per-worker timelines of a few steps (`bench-sph trace`);
//! - [`validate`]: the `wcsph` dam break against Martin & Moyce (1952) (`bench-sph validate`).

pub mod clock;
pub mod contention;
pub mod io;
pub mod limits;
pub mod merge;
pub mod output;
pub mod placement;
pub mod results;
pub mod run;
pub mod signals;
pub mod sweep;
pub mod topology;
pub mod trace;
pub mod validate;
