//! Müller, Charypar & Gross (2003) as the seed paper's Haskell program and the C++ original
//! compute it, in pixel units: the `seed` and `cpp` presets ([`params`]), what a step computes
//! for each particle ([`passes`], pure), the solver's view of it ([`model`]: two passes a
//! step, the second writing each particle's new motion into [`next_motion`]) and the dam
//! break it starts from ([`scene`]).

pub mod model;
pub mod next_motion;
pub mod params;
pub mod passes;
pub mod scene;
