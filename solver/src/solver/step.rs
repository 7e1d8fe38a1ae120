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

use super::model::Model;
use super::{Pass, Simulation, StepError};
use crate::models::with_model;
use crate::simd::Lanes;
use crate::with_lanes;

/// What a kernel call computes: part of the neighbour search's rebuild (the grid's, which
/// runs its per-particle parts on the executor), or one of the model's passes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Phase {
    /// The neighbour search's rebuild, before the density pass.
    Rebuild,
    /// A pass.
    Pass(Pass),
}

impl Phase {
    /// Every phase: the rebuild, then every pass ([`Pass::ALL`]).
    pub const ALL: [Phase; 9] = [
        Phase::Rebuild,
        Phase::Pass(Pass::Density),
        Phase::Pass(Pass::Forces),
        Phase::Pass(Pass::Integrate),
        Phase::Pass(Pass::MaxSpeed),
        Phase::Pass(Pass::Neighbors),
        Phase::Pass(Pass::Walls),
        Phase::Pass(Pass::Momentum),
        Phase::Pass(Pass::Continuity),
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

/// From this many particles on, the divergence check runs on the executor.
const PARALLEL_CHECK: usize = 1 << 16;

/// Particles per block of the parallel divergence check.
const CHECK_BLOCK: usize = 4096;

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
            let passes = self.passes().iter().map(|&p| Phase::Pass(p));
            for phase in std::iter::once(Phase::Rebuild).chain(passes) {
                let job = Job { sim: self, phase };
                hooks
                    .phase(exec, phase, step, job)
                    .map_err(|source| StepError::Kernel { step, source })?;
            }
            self.steps_done = step;
            self.time_s += self.last_dt();
            if let Some(error) = hooks.check(step, || self.first_fault(exec, step)) {
                return Err(error);
            }
        }
        Ok(())
    }

    /// Runs steps on `exec`, each phase and check through `hooks`, until the simulated time
    /// reaches `t_end` (s) or `max_steps` have run; returns the steps run. Stops at the first
    /// failing step, as [`Simulation::advance_with`].
    pub fn advance_until<E: Executor, H: StepHooks>(
        &mut self,
        exec: &E,
        max_steps: usize,
        t_end: f64,
        hooks: &mut H,
    ) -> Result<usize, StepError> {
        let mut ran = 0;
        while ran < max_steps && self.time_s < t_end {
            self.advance_with(exec, 1, hooks)?;
            ran += 1;
        }
        Ok(ran)
    }

    /// What makes step `step` a failure, if anything: a non-finite value, or (WCSPH) a fluid
    /// particle outside the tank or with a density ≤ 0.
    fn first_fault<E: Executor>(&self, exec: &E, step: usize) -> Option<StepError> {
        let divergence = match self.first_divergence(exec) {
            Ok(found) => found,
            Err(source) => return Some(StepError::Kernel { step, source }),
        };
        if let Some((field, particle)) = divergence {
            return Some(StepError::Diverged {
                step,
                particle,
                field,
            });
        }
        let (particle, what) = self.first_unphysical()?;
        Some(StepError::Unphysical {
            step,
            particle,
            what,
        })
    }

    /// The first non-finite field and particle, if any. A large state is scanned in blocks
    /// on `exec` (the scan reads 32 bytes a particle: at N = 10⁶ it was a tenth of a step,
    /// run serially); a small one on this thread, where a pass would cost more than it saves.
    fn first_divergence<E: Executor>(
        &self,
        exec: &E,
    ) -> Result<Option<(&'static str, usize)>, KernelPanic> {
        // In Müller's model any non-finite density, pressure, force or position makes the
        // particle's own velocity non-finite in the same step; in WCSPH a non-finite density
        // or pressure (the seventh power can overflow) reaches the velocities only a step
        // later. So checking velocities, densities and pressures (4 arrays rather than 8)
        // catches every divergence in the step it happens; the full scan then names the
        // first field.
        let (s, lanes) = (&self.state, self.lanes);
        let finite = if s.len() < PARALLEL_CHECK {
            with_lanes!(lanes, l => l.vectorize(
                #[inline(always)]
                || s.guarded_fields_finite(0..s.len())
            ))
        } else {
            let mut ok = vec![true; s.len().div_ceil(CHECK_BLOCK)];
            exec.for_each_chunk(&mut ok[..], |first, ok| {
                for (b, ok) in ok.iter_mut().enumerate() {
                    let start = (first + b) * CHECK_BLOCK;
                    let block = start..(start + CHECK_BLOCK).min(s.len());
                    *ok = with_lanes!(lanes, l => l.vectorize(
                        #[inline(always)]
                        || s.guarded_fields_finite(block)
                    ));
                }
            })?;
            ok.iter().all(|&ok| ok)
        };
        Ok(if finite { None } else { s.first_non_finite() })
    }

    /// The first particle that left what the model describes ([`Model::first_unphysical`]).
    fn first_unphysical(&self) -> Option<(usize, &'static str)> {
        with_model!(&self.physics, m => m.first_unphysical(&self.state, self.domain))
    }
}
