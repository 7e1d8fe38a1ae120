//! Fault injection for tests (`simulate --inject-panic-at`): a wrapping executor, like the
//! trace's, so the solver carries no test flag and runs without it pay nothing. Compiled only
//! with the `testing` feature: its step loop is a copy of the solver for every strategy, which
//! the shipped binary does not carry.

use sph_strategies::{Config, Executor, KernelPanic, Split, StrategyName};

use super::{RunError, Steps};
use crate::clock::Elapsed;
use sph_solver::solver::{Pass, Phase, PhaseJob, Simulation, StepHooks};

/// [`super::run_timed_steps`] with [`PanicAt`]`(particle)`'s fault in every step.
pub fn run_timed_steps_panicking_at(
    sim: &mut Simulation,
    strategy: StrategyName,
    config: &Config,
    steps: Steps,
    particle: usize,
) -> Result<Elapsed, RunError> {
    super::run_timed_steps_with(sim, strategy, config, steps, &mut PanicAt(particle))
}

/// Step hooks that make the density pass's kernel panic with `injected fault at particle I`
/// in the call whose chunk holds particle `I`, before it computes anything, in every step.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PanicAt(pub usize);

impl StepHooks for PanicAt {
    fn phase<E: Executor, J: PhaseJob>(
        &mut self,
        exec: &E,
        phase: Phase,
        _step: usize,
        job: J,
    ) -> Result<(), KernelPanic> {
        if phase == Phase::Pass(Pass::Density) {
            job.run_on(&Faulty {
                inner: exec,
                particle: self.0,
            })
        } else {
            job.run_on(exec)
        }
    }
}

/// Runs passes on `inner`, panicking in the kernel call whose chunk holds `particle`.
struct Faulty<'a, E> {
    inner: &'a E,
    particle: usize,
}

impl<E: Executor> Executor for Faulty<'_, E> {
    fn for_each_chunk<O, F>(&self, out: O, kernel: F) -> Result<(), KernelPanic>
    where
        O: Split,
        F: Fn(usize, O) + Sync,
    {
        let particle = self.particle;
        self.inner.for_each_chunk(out, |first, chunk| {
            if (first..first + chunk.len()).contains(&particle) {
                panic!("injected fault at particle {particle}");
            }
            kernel(first, chunk);
        })
    }

    fn threads(&self) -> usize {
        self.inner.threads()
    }
}
