//! bench-sph: a 2D SPH dam-break solver (Müller 2003, as ported by the seed paper, and a
//! weakly compressible SPH validated against experiment) behind interchangeable parallel
//! strategies, and the tools to measure them.
//!
//! The workspace's crates are its layers; this one is the top: the `bench-sph` command line
//! ([`cli`]) over the crates below, whose modules it re-exports so that one path names each:
//!
//! - `sph-strategies`: the parallel strategies, knowing nothing of SPH;
//! - `sph-solver`: the physics ([`models`], [`sph`], [`simd`], [`solver`], [`scene`],
//!   [`checksum`]);
//! - `sph-harness`: what measures and keeps ([`run`], [`clock`], [`contention`],
//!   [`topology`], [`placement`], [`limits`], [`io`], [`output`], [`signals`], [`sweep`],
//!   [`results`], [`merge`], [`trace`], [`validate`]);
//! - `sph-report`: words and pictures ([`report`], [`plot`], [`render`], and `viewer` with the
//!   cargo feature `viewer`).

pub use sph_harness::{
    clock, contention, io, limits, merge, output, placement, results, run, signals, sweep,
    topology, trace, validate,
};
#[cfg(feature = "viewer")]
pub use sph_report::viewer;
pub use sph_report::{plot, render, report};
pub use sph_solver::{checksum, models, scene, simd, solver, sph, with_lanes};

pub mod cli;
