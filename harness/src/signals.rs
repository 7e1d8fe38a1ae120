//! What a command does when it is asked to stop: Ctrl-C (SIGINT), SIGTERM (`timeout`, a
//! batch system's time limit, `kill`) and SIGHUP (the terminal closed) are handled alike.
//!
//! - A sweep ([`Stop::BetweenRuns`]) stops after the run in progress, keeps every run
//!   measured and marks itself `interrupted`; a second signal quits at once (the runs already
//!   written are kept).
//! - Every other command ([`Stop::Now`]) removes its half-written temporary files and exits
//!   at once with 128 + the signal's number (130 for Ctrl-C), each destination keeping its
//!   earlier contents.
//!
//! A SIGHUP that was ignored when the command started stays ignored: under `nohup` a closed
//! terminal does not stop a sweep. (Linux says which signals are ignored in
//! `/proc/self/status`; elsewhere SIGHUP is handled.)

use std::sync::Once;
use std::sync::atomic::{AtomicBool, Ordering};

use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
use signal_hook::iterator::Signals;

use crate::output::console::warn;

/// What a signal does to this command.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stop {
    /// Ask the command to stop between runs ([`requested`]); a second signal exits.
    BetweenRuns,
    /// Remove the temporary files being written and exit.
    Now,
}

/// Set by the first signal under [`Stop::BetweenRuns`].
static REQUESTED: AtomicBool = AtomicBool::new(false);

/// Whether a signal asked the command to stop.
pub fn requested() -> bool {
    REQUESTED.load(Ordering::SeqCst)
}

/// Handles the three signals as `stop` says, from a thread of its own. The first call wins;
/// later calls do nothing (a process has one way to stop). If the handlers cannot be
/// installed, the signals keep their default action (the process ends).
pub fn install(stop: Stop) {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        let mut wanted = vec![SIGINT, SIGTERM];
        if !sighup_ignored_at_start() {
            wanted.push(SIGHUP);
        }
        let Ok(mut signals) = Signals::new(&wanted) else {
            return;
        };
        let _ = std::thread::Builder::new()
            .name("signals".to_owned())
            .spawn(move || {
                for signal in signals.forever() {
                    on_signal(stop, signal);
                }
            });
    });
}

/// The signal's name as a user would know it.
fn name(signal: i32) -> &'static str {
    match signal {
        SIGINT => "Ctrl-C",
        SIGTERM => "SIGTERM",
        SIGHUP => "SIGHUP",
        _ => "a signal",
    }
}

fn on_signal(stop: Stop, signal: i32) {
    let name = name(signal);
    match stop {
        Stop::Now => {
            crate::output::atomic::remove_live_temporaries();
            warn(&format!("\n{name}: stopped; nothing was written"));
            std::process::exit(128 + signal);
        }
        Stop::BetweenRuns if REQUESTED.swap(true, Ordering::SeqCst) => {
            warn(&format!(
                "\n{name} again: quitting now; the runs written are kept (--resume continues)"
            ));
            std::process::exit(128 + signal);
        }
        Stop::BetweenRuns => warn(&format!(
            "\n{name}: stopping after the current run; the cell in progress is discarded \
             (Ctrl-C again to quit at once)"
        )),
    }
}

/// Whether SIGHUP was ignored when this process started (`nohup` ignores it, and a child
/// inherits that): the `SigIgn` mask of `/proc/self/status`. False where that cannot be read.
/// A command started from such a process keeps running when its terminal closes.
pub fn sighup_ignored_at_start() -> bool {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|status| ignored_in(&status, SIGHUP))
        .unwrap_or(false)
}

/// The `SigIgn` line of a `/proc/PID/status` text, asked about `signal`.
fn ignored_in(status: &str, signal: i32) -> Option<bool> {
    let mask = status
        .lines()
        .find_map(|line| line.strip_prefix("SigIgn:"))?
        .trim();
    let mask = u64::from_str_radix(mask, 16).ok()?;
    let bit = u32::try_from(signal.checked_sub(1)?).ok()?;
    Some(mask.checked_shr(bit)? & 1 == 1)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_ignored_mask_is_read_one_bit_per_signal_from_one() {
        let nohup = "Name:\tbench-sph\nSigBlk:\t0000000000000000\nSigIgn:\t0000000000000001\n";
        assert_eq!(ignored_in(nohup, SIGHUP), Some(true));
        assert_eq!(ignored_in(nohup, SIGINT), Some(false));
        let script = "SigIgn:\t0000000000000006\n";
        assert_eq!(ignored_in(script, SIGHUP), Some(false));
        assert_eq!(ignored_in(script, SIGINT), Some(true));
        assert_eq!(ignored_in("Name:\tx\n", SIGHUP), None);
        assert_eq!(ignored_in("SigIgn:\tzz\n", SIGHUP), None);
    }
}
