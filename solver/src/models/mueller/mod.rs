//! Müller, Charypar & Gross (2003) as the seed paper's Haskell program and the C++ original
//! compute it, in pixel units: the `seed` and `cpp` presets ([`params`]), the three passes of a
//! step ([`passes`], pure), the solver's view of it ([`model`]) and the dam break it starts
//! from ([`scene`]).

pub mod model;
pub mod params;
pub mod passes;
pub mod scene;
