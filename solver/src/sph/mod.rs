//! What every model shares: the particle state and the neighbour search (all pairs, or a
//! grid). Everything here is pure; the models are in [`crate::models`], threads and timing
//! elsewhere.

pub mod neighbors;
pub mod state;
