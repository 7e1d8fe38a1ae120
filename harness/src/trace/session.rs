//! A traced run: the one step loop ([`crate::run`]) with hooks that run every phase of every
//! step on a [`TracingExecutor`] and time the divergence check, so that every kernel call is
//! known to belong to one pass of one step.
//!
//! Both traced and untraced runs here first **warm up** the strategy's threads
//! ([`crate::run::Steps::warmup`]): a few untimed, unrecorded steps on a copy of the initial
//! state, on the same pool, right before the recorded steps. A freshly built pool's threads
//! are still starting or asleep, and a first few steps of small chunks can then all run on the
//! thread that started them; the committed `rayon-chunks` timeline once showed 405 kernel
//! calls on one of two workers for that reason. The copy leaves the recorded steps exactly
//! those of an untraced run from the same state.

use sph_strategies::{Config, Executor, KernelPanic, StrategyName};

use super::executor::TracingExecutor;
use super::recorder::{Phase, Recorder, SerialWork, Trace};
use super::size::{MAX_EVENTS, Plan};
use crate::clock::Elapsed;
use crate::run::{RunError, run_timed_with};
use sph_solver::solver::{PhaseJob, Simulation, StepHooks};
use sph_solver::sph::neighbors::NeighborMode;

/// What a traced run gives back.
#[derive(Debug)]
pub struct TracedRun {
    /// Wall and CPU time of the step loop, recording included.
    pub elapsed: Elapsed,
    /// What was recorded.
    pub trace: Trace,
}

/// The kernel calls one worker is expected to make (from [`Plan::kernel_calls`], counting the
/// grid rebuild's calls whichever search runs), used only to preallocate its event buffer
/// (buffers still grow if it is short).
fn capacity_hint(
    strategy: StrategyName,
    config: &Config,
    n: usize,
    steps: usize,
    passes: usize,
) -> usize {
    let total = Plan {
        strategy,
        n,
        chunks: config.chunks,
        cores: config.cores,
        steps,
        passes,
        neighbors: NeighborMode::Grid,
    }
    .kernel_calls();
    // Twice a fair share, so that a moderately unbalanced run never reallocates, but never
    // more than `MAX_EVENTS` preallocated over all workers (a buffer that fills grows).
    let workers = strategy.info().effective_cores(config.cores);
    total
        .saturating_mul(2)
        .div_ceil(workers)
        .min(total)
        .min(MAX_EVENTS / workers)
}

/// Step hooks that record: each phase runs on a [`TracingExecutor`], and the grid rebuild and
/// the divergence check are timed as the calling thread's serial work. The recorded window
/// runs from the first rebuild's start to the last check's end.
struct Tracing<'a> {
    recorder: &'a Recorder,
    window: Option<(u64, u64)>,
}

impl StepHooks for Tracing<'_> {
    fn phase<E: Executor, J: PhaseJob>(
        &mut self,
        exec: &E,
        phase: Phase,
        step: usize,
        job: J,
    ) -> Result<(), KernelPanic> {
        let rec = self.recorder;
        let t = rec.now_ns();
        self.window.get_or_insert((t, t));
        job.run_on(&TracingExecutor::new(exec, rec, phase, step))?;
        if phase == Phase::Rebuild {
            rec.record_serial(SerialWork::Rebuild, step, t, rec.now_ns());
        }
        Ok(())
    }

    fn check<R>(&mut self, step: usize, check: impl FnOnce() -> R) -> R {
        let rec = self.recorder;
        let t = rec.now_ns();
        let result = check();
        let end = rec.now_ns();
        rec.record_serial(SerialWork::Check, step, t, end);
        if let Some(window) = &mut self.window {
            window.1 = end;
        }
        result
    }
}

/// Runs `warmup` unrecorded steps on a copy of `sim`, then `steps` steps of `sim` with
/// `strategy`, recording every kernel call (and the caller's grid rebuild and divergence
/// check), and returns the timing and the trace. The caller checks the trace's size first
/// ([`Plan::check`]).
///
/// The physics is exactly that of an untraced run (the same passes, chunks and threads), so
/// the final state has the same bits.
pub fn run_traced(
    sim: &mut Simulation,
    strategy: StrategyName,
    config: &Config,
    steps: usize,
    warmup: usize,
) -> Result<TracedRun, RunError> {
    let workers = strategy.info().effective_cores(config.cores);
    let per_worker = capacity_hint(strategy, config, sim.state.len(), steps, sim.passes().len());
    let recorder = Recorder::new(workers, per_worker, 2 * steps);
    let mut hooks = Tracing {
        recorder: &recorder,
        window: None,
    };
    let elapsed = run_timed_with(sim, strategy, config, steps, warmup, &mut hooks)?;
    let (start, end) = hooks.window.unwrap_or_else(|| {
        let now = recorder.now_ns();
        (now, now)
    });
    Ok(TracedRun {
        elapsed,
        trace: recorder.finish(start, end, workers),
    })
}

/// [`run_traced`] without the recording: the same warm-up, then `steps` timed steps. The
/// untraced side of `trace --compare`.
pub fn run_untraced(
    sim: &mut Simulation,
    strategy: StrategyName,
    config: &Config,
    steps: usize,
    warmup: usize,
) -> Result<Elapsed, RunError> {
    run_timed_with(sim, strategy, config, steps, warmup, &mut ())
}
