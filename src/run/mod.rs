//! A timed run: the step loop of a [`Simulation`] on a named strategy.
//!
//! The timed region is the step loop only (grid rebuilds, spawns, barriers and the divergence
//! check included); building the initial state and the thread pool, the checksum and the dump
//! are outside it. CPU time is the process's user + system time over the same window.

use sph_strategies::{Config, Executor, Session, StrategyName};

use crate::clock::{Elapsed, Stopwatch};
use crate::solver::{Simulation, StepError};

/// Why a run failed.
#[derive(Debug, thiserror::Error)]
pub enum RunError {
    /// The strategy could not be built (bad cores/chunks, no threads).
    #[error("strategy {strategy}")]
    Build {
        /// The strategy.
        strategy: StrategyName,
        /// Why.
        source: sph_strategies::BuildError,
    },
    /// A step failed.
    #[error(transparent)]
    Step(#[from] StepError),
}

struct TimedSteps<'a> {
    sim: &'a mut Simulation,
    steps: usize,
}

impl Session for TimedSteps<'_> {
    type Output = Result<Elapsed, StepError>;

    fn run<E: Executor>(self, exec: &E) -> Self::Output {
        let watch = Stopwatch::start();
        self.sim.advance(exec, self.steps)?;
        Ok(watch.stop())
    }
}

/// Runs `steps` steps of `sim` with `strategy` and returns the time they took.
pub fn run_timed(
    sim: &mut Simulation,
    strategy: StrategyName,
    config: &Config,
    steps: usize,
) -> Result<Elapsed, RunError> {
    let session = TimedSteps { sim, steps };
    let result = sph_strategies::run(strategy, config, session)
        .map_err(|source| RunError::Build { strategy, source })?;
    Ok(result?)
}
