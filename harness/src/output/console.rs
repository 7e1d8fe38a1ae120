//! Standard output that may be closed under us: `bench-sph sweep | head -2`, or `> /dev/full`.
//!
//! Rust's `println!` panics when standard output is gone. Commands print through [`line()`]
//! instead: a failed write returns the error, and records that standard output is closed
//! ([`closed`]) so that a long command (a sweep) can stop cleanly, as after Ctrl-C, keeping
//! what it finished. [`plural`] words a count the one way every command's messages share.

use std::io::Write;
use std::sync::atomic::{AtomicBool, Ordering};

static CLOSED: AtomicBool = AtomicBool::new(false);

/// Writes `text` and a newline to standard output and flushes it. On failure (a closed
/// pipe, a full device) returns the error and marks standard output [`closed`].
pub fn line(text: &str) -> std::io::Result<()> {
    let mut out = std::io::stdout().lock();
    let result = writeln!(out, "{text}").and_then(|()| out.flush());
    if result.is_err() {
        CLOSED.store(true, Ordering::SeqCst);
    }
    result
}

/// Whether a write to standard output has failed.
pub fn closed() -> bool {
    CLOSED.load(Ordering::SeqCst)
}

/// Writes `text` and a newline to standard error, ignoring failure (warnings must never end
/// a command).
pub fn warn(text: &str) {
    let _ = writeln!(std::io::stderr().lock(), "{text}");
}

/// `1 warm-up` / `3 warm-ups`, and so on.
pub fn plural(count: usize, one: &str, many: &str) -> String {
    format!("{count} {}", if count == 1 { one } else { many })
}
