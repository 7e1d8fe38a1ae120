//! The one step loop ([`Simulation::advance_with`]): every run — timed, traced, rendered,
//! viewed, benchmarked — steps through it, so the order of a step's phases and the divergence
//! guard exist once.
//!
//! What a caller adds to a step goes through [`StepHooks`], never through a flag in the
//! solver: a hook may run each phase on an executor wrapping the strategy's (the trace's
//! `TracingExecutor`, the fault injection of `simulate --inject-panic-at`) and may wrap the
//! divergence check (the trace times it). Hooks are static: the plain loop
//! ([`Simulation::advance`], hooks `()`) compiles to the calls it always made.

use sph_strategies::{Executor, KernelPanic};

use super::{Pass, Simulation, StepError};

/// What a kernel call computes: part of the neighbour search's rebuild (the grid's, which
/// runs its per-particle parts on the executor), or one of the three passes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Phase {
    /// The neighbour search's rebuild, before the density pass.
    Rebuild,
    /// A pass.
    Pass(Pass),
}

impl Phase {
    /// Every phase in step order.
    pub const ALL: [Phase; 4] = [
        Phase::Rebuild,
        Phase::Pass(Pass::Density),
        Phase::Pass(Pass::Forces),
        Phase::Pass(Pass::Integrate),
    ];

    /// Name, as in trace.json, stats.csv and the timeline's legend: `grid rebuild` or the
    /// pass's name.
    pub fn as_str(self) -> &'static str {
        match self {
            Phase::Rebuild => "grid rebuild",
            Phase::Pass(p) => p.as_str(),
        }
    }
}

impl From<Pass> for Phase {
    fn from(p: Pass) -> Self {
        Phase::Pass(p)
    }
}

/// One phase of one step, ready to run on whichever executor a [`StepHooks`] picks.
pub trait PhaseJob {
    /// Runs the phase on `exec`.
    fn run_on<E: Executor>(self, exec: &E) -> Result<(), KernelPanic>;
}

/// What a caller adds around the parts of each step. The defaults add nothing.
pub trait StepHooks {
    /// Runs `job`, phase `phase` of (1-based) step `step`, on `exec` or on an executor that
    /// wraps it (which must hand every chunk to the kernel as `exec` cut it).
    fn phase<E: Executor, J: PhaseJob>(
        &mut self,
        exec: &E,
        phase: Phase,
        step: usize,
        job: J,
    ) -> Result<(), KernelPanic> {
        let _ = (phase, step);
        job.run_on(exec)
    }

    /// Runs `check`, the divergence check after step `step`, and returns its result.
    fn check<R>(&mut self, step: usize, check: impl FnOnce() -> R) -> R {
        let _ = step;
        check()
    }
}

/// No hooks: the plain step loop.
impl StepHooks for () {}

/// A phase of a step of one simulation.
struct Job<'a> {
    sim: &'a mut Simulation,
    phase: Phase,
}

impl PhaseJob for Job<'_> {
    fn run_on<E: Executor>(self, exec: &E) -> Result<(), KernelPanic> {
        match self.phase {
            Phase::Rebuild => self.sim.rebuild_neighbors_on(exec),
            Phase::Pass(pass) => self.sim.run_pass(exec, pass),
        }
    }
}

impl Simulation {
    /// Runs `steps` steps on `exec`. Stops at the first failing step.
    pub fn advance<E: Executor>(&mut self, exec: &E, steps: usize) -> Result<(), StepError> {
        self.advance_with(exec, steps, &mut ())
    }

    /// Runs `steps` steps on `exec`, each phase and check through `hooks`. Stops at the first
    /// failing step: a kernel's panic, or a non-finite value after the step (the step then
    /// counts as done, so the state shows it).
    pub fn advance_with<E: Executor, H: StepHooks>(
        &mut self,
        exec: &E,
        steps: usize,
        hooks: &mut H,
    ) -> Result<(), StepError> {
        for _ in 0..steps {
            let step = self.steps_done + 1;
            for phase in Phase::ALL {
                let job = Job { sim: self, phase };
                hooks
                    .phase(exec, phase, step, job)
                    .map_err(|source| StepError::Kernel { step, source })?;
            }
            self.steps_done = step;
            if let Some((field, particle)) = hooks.check(step, || self.first_divergence()) {
                return Err(StepError::Diverged {
                    step,
                    particle,
                    field,
                });
            }
        }
        Ok(())
    }

    /// The first non-finite field and particle, if any.
    fn first_divergence(&self) -> Option<(&'static str, usize)> {
        // Any non-finite density, pressure, force or position makes the particle's own
        // velocity non-finite in the same step, so checking velocities (2 arrays rather than
        // 8) catches every divergence; the full scan then names the first field.
        if self.state.velocities_finite() {
            return None;
        }
        self.state.first_non_finite()
    }
}
