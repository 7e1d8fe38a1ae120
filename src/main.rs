//! The `bench-sph` command.

use std::process::ExitCode;

fn main() -> ExitCode {
    match bench_sph::cli::run() {
        Ok(()) => ExitCode::SUCCESS,
        Err(err) => {
            eprintln!("Error: {err:#}");
            ExitCode::FAILURE
        }
    }
}
