//! The physics: constants, state, neighbour search and the three per-particle passes.
//! Everything here is pure; threads and timing live elsewhere.

pub mod neighbors;
pub mod params;
pub mod passes;
pub mod state;
