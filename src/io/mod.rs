//! Reading an initial state from CSV and writing a final state to CSV, and where a command's
//! output file goes.

pub mod bounded;
pub mod dump_csv;
pub mod init_csv;
pub mod sink;
