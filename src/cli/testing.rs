//! Test hooks: options that exist only in a build with the `testing` cargo feature, which the
//! integration tests enable (`cargo test --profile ci --workspace --all-features`). The shipped
//! binary (`cargo install --path . --locked`) does not know them: `--fake-timings` there is an
//! unknown argument, and nothing of them reaches a real sweep's `meta.json`.
//!
//! Each command's hooks are one struct, flattened into its options under the feature and
//! read through one function that answers "no hook" without it, so the rest of the code is
//! the same in both builds.

use clap::Args;

/// `sweep`'s hooks.
#[derive(Debug, Clone, Default, Args)]
pub struct SweepHooks {
    /// Record these times (WALL or WALL:CPU seconds, comma-separated, taken in turn) instead
    /// of the measured ones. The runs still happen and are checked.
    #[arg(long, value_name = "LIST")]
    pub fake_timings: Option<String>,
    /// Record these shares (0 ..= 1, comma-separated, taken in turn) of the machine's
    /// capacity as taken by other work, instead of the measured foreign CPU.
    #[arg(long, value_name = "LIST")]
    pub fake_contention: Option<String>,
    /// Stop as if Ctrl-C was pressed once this many runs are written.
    #[arg(long, value_name = "K")]
    pub stop_after_runs: Option<usize>,
}

/// `simulate`'s hooks.
#[derive(Debug, Clone, Default, Args)]
pub struct SimulateHooks {
    /// Make the density kernel panic at this particle, to check that a worker's panic
    /// becomes an error of the run on every strategy.
    #[arg(long, value_name = "PARTICLE")]
    pub inject_panic_at: Option<usize>,
}
