//! The physics: constants, state, neighbour search and the per-particle passes of both
//! models — Müller's pixel-unit fluid (the `seed` and `cpp` presets: `params`, `passes`) and
//! weakly compressible SPH in SI units (the `wcsph` preset: `wcsph`). Everything here is pure;
//! threads and timing live elsewhere.

pub mod neighbors;
pub mod params;
pub mod passes;
pub mod state;
pub mod wcsph;
