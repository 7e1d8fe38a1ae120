//! Initial states: the presets' dam-break layouts and the domain they live in.

pub mod dam_break;
pub mod splitmix;
