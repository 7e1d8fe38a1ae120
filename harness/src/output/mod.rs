//! How every command writes what it produces, so that nothing is lost:
//!
//! - [`atomic`]: each file is written to a temporary name in its own directory and renamed
//!   over the destination only when complete — a crash, a Ctrl-C or a full disk leaves the
//!   previous file (or none), never half a file;
//! - [`lock`]: one writer per directory — every command that writes a directory holds its
//!   lock for as long as it writes, and a second writer is refused naming the first;
//! - [`record`]: each directory's record of the files bench-sph wrote there, and which
//!   command wrote each;
//! - [`claim`]: a command that writes into a directory first locks it and sorts its entries
//!   by the record, refuses one holding files it did not write (unless `--force`, and even
//!   then replaces only its own), and removes its own stale files afterwards;
//! - [`console`]: standard output that may be closed under us (`| head`, `> /dev/full`);
//! - [`digits`]: numbers for a reader, at most three significant digits;
//! - [`sniff`]: recognising a file's format by its first bytes (a trace's PNG).

pub mod atomic;
pub mod claim;
pub mod console;
pub mod digits;
pub mod lock;
pub mod record;
pub mod sniff;
