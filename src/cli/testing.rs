//! Test hooks: options that exist only in a build with the `testing` cargo feature, which the
//! integration tests enable (`cargo test --profile ci --workspace --all-features`). The shipped
//! binary (`cargo install --path . --locked`) does not know them: `--fake-timings` there is an
//! unknown argument, and nothing of them reaches a real sweep's `meta.json`.
//!
//! Each command's hooks are one struct, flattened into its options under the feature and
//! read through one function that answers "no hook" without it, so the rest of the code is
//! the same in both builds.

use clap::Args;
use sph_strategies::{Config, StrategyName};

use crate::clock::Elapsed;
use crate::run::{RunError, Steps, run_timed_steps};
use crate::solver::Simulation;

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

impl SimulateHooks {
    /// `simulate`'s run ([`run_timed_steps`]), with the kernel panic injected where asked. Only
    /// a build with the `testing` feature compiles the injecting run (a step loop of its own
    /// for every strategy); the shipped binary runs the plain one.
    pub fn run_timed_steps(
        &self,
        sim: &mut Simulation,
        strategy: StrategyName,
        config: &Config,
        steps: Steps,
    ) -> Result<Elapsed, RunError> {
        #[cfg(feature = "testing")]
        if let Some(particle) = self.inject_panic_at {
            return crate::run::fault::run_timed_steps_panicking_at(
                sim, strategy, config, steps, particle,
            );
        }
        run_timed_steps(sim, strategy, config, steps)
    }
}
