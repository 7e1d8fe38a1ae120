//! Reading an initial state from CSV and writing a final state to CSV, where a command's
//! output file goes, and the one way every file of a results, trace or output directory is
//! read ([`capped`]: regular files only, at most a cap per kind).

pub mod capped;
pub mod sink;
pub use sph_solver::io::{bounded, dump_csv, init_csv};
