//! The `bench-sph` command.

use std::io::Write;
use std::process::ExitCode;

/// Writes a line to standard error, ignoring failure: with standard error closed too
/// (`bench-sph sweep 2>&1 | head`), there is nobody left to tell, and `eprintln!` would panic.
fn tell(text: &str) {
    let _ = writeln!(std::io::stderr().lock(), "{text}");
}

fn main() -> ExitCode {
    // A panic is a bug. Strategies turn a kernel's panic into an error of the run; this hook
    // only says where it happened, on one line, without the backtrace hint.
    std::panic::set_hook(Box::new(|info| {
        let location = info
            .location()
            .map_or_else(String::new, |l| format!(" at {l}"));
        let message = info
            .payload()
            .downcast_ref::<&str>()
            .map(|s| (*s).to_owned())
            .or_else(|| info.payload().downcast_ref::<String>().cloned())
            .unwrap_or_default();
        tell(&format!("bench-sph: internal panic{location}: {message}"));
    }));
    match bench_sph::cli::run() {
        Ok(()) => ExitCode::SUCCESS,
        Err(err) => {
            tell(&format!("Error: {err:#}"));
            ExitCode::FAILURE
        }
    }
}
