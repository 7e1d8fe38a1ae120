//! A state in and out as CSV: [`init_csv`] reads `--init` files (every line and the file
//! bounded: [`bounded`]), [`dump_csv`] writes `--dump` files.

pub mod bounded;
pub mod dump_csv;
pub mod init_csv;
