//! Initial states: the presets' dam-break layouts and the domain they live in, and the memory
//! a run of them needs.

pub mod dam_break;
pub mod memory;
pub mod splitmix;
