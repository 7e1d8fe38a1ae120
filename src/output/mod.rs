//! How every command writes what it produces, so that nothing is lost:
//!
//! - [`atomic`]: each file is written to a temporary name in its own directory and renamed
//!   over the destination only when complete — a crash, a Ctrl-C or a full disk leaves the
//!   previous file (or none), never half a file;
//! - [`claim`]: a command that writes into a directory first checks what the directory
//!   holds, refuses one holding files it did not write (unless `--force`, and even then
//!   replaces only its own), and removes its own stale files afterwards;
//! - [`console`]: standard output that may be closed under us (`| head`, `> /dev/full`);
//! - [`sniff`]: recognising a file by its first bytes, so that only a command's own files are
//!   replaced.

pub mod atomic;
pub mod claim;
pub mod console;
pub mod sniff;
