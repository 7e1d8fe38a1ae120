//! Reading an initial state from CSV and writing a final state to CSV.

pub mod dump_csv;
pub mod init_csv;
