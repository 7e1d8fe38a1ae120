//! sph-solver: the 2D SPH dam break that bench-sph measures — Müller 2003 as the seed paper
//! ports it (`seed`, `cpp`) and a weakly compressible SPH validated against experiment
//! (`wcsph`) — run by any of the strategies of `sph-strategies`.
//!
//! - [`models`]: each model in its folder (constants, pure per-particle passes, the
//!   solver's view of it, its dam break) and the registry of models;
//! - [`sph`]: what the models share: the particle state and the neighbour search;
//! - [`simd`]: the instruction sets the neighbour tests run on, picked at start-up;
//! - [`solver`]: one step as the model's passes run by a strategy's executor;
//! - [`scene`]: a preset and a size → an initial state, and the memory its run needs;
//! - [`io`]: a state from CSV (`--init`) and to CSV (`--dump`);
//! - [`checksum`]: a state's bits in one number, to compare strategies.
//!
//! This crate is the bottom layer: it knows nothing of the harness, the report or the
//! command line (the workspace's dependencies keep it so; `tests/it/layers.rs` checks it).

pub mod checksum;
#[cfg(test)]
mod cutting;
pub mod io;
pub mod models;
pub mod scene;
pub mod simd;
pub mod solver;
pub mod sph;

/// The most particles any command accepts (memory is checked separately:
/// [`scene::memory`]).
pub const MAX_PARTICLES: usize = 100_000_000;
