//! A traced run: the same step loop as [`crate::run::run_timed`], pass by pass, so that every
//! kernel call is known to belong to one pass of one step.
//!
//! Both traced and untraced runs here first **warm up** the strategy's threads: a few
//! untimed, unrecorded steps on a copy of the initial state, on the same pool, right before
//! the recorded steps. A freshly built pool's threads are still starting or asleep, and a
//! first few steps of small chunks can then all run on the thread that started them; the
//! committed `rayon-chunks` timeline once showed 405 kernel calls on one of two workers for
//! that reason. The copy leaves the recorded steps exactly those of an untraced run from the
//! same state.

use sph_strategies::{Config, Executor, Session, StrategyName};

use super::executor::TracingExecutor;
use super::recorder::{Phase, Recorder, SerialWork, Trace};
use super::size::{MAX_EVENTS, Plan};
use crate::clock::{Elapsed, Stopwatch};
use crate::run::RunError;
use crate::solver::{Pass, Simulation, StepError};
use crate::sph::neighbors::NeighborMode;

/// What a traced run gives back.
#[derive(Debug)]
pub struct TracedRun {
    /// Wall and CPU time of the step loop, recording included.
    pub elapsed: Elapsed,
    /// What was recorded.
    pub trace: Trace,
}

/// The number of worker tracks a strategy is expected to use: 1 for `seq`, `cores` otherwise.
pub fn expected_workers(strategy: StrategyName, cores: usize) -> usize {
    if strategy == StrategyName::Seq {
        1
    } else {
        cores
    }
}

/// The kernel calls one worker is expected to make (from [`Plan::kernel_calls`], counting the
/// grid rebuild's calls whichever search runs), used only to preallocate its event buffer
/// (buffers still grow if it is short).
fn capacity_hint(strategy: StrategyName, config: &Config, n: usize, steps: usize) -> usize {
    let total = Plan {
        strategy,
        n,
        chunks: config.chunks,
        cores: config.cores,
        steps,
        neighbors: NeighborMode::Grid,
    }
    .kernel_calls();
    // Twice a fair share, so that a moderately unbalanced run never reallocates, but never
    // more than `MAX_EVENTS` preallocated over all workers (a buffer that fills grows).
    let workers = expected_workers(strategy, config.cores);
    total
        .saturating_mul(2)
        .div_ceil(workers)
        .min(total)
        .min(MAX_EVENTS / workers)
}

/// Runs `steps` steps of a copy of `sim` on `exec`, discarding the copy. A copy that diverges
/// only ends the warm-up early (the recorded run reports its own divergence, if it reaches
/// it); a kernel's panic is an error.
fn warm_up<E: Executor>(exec: &E, sim: &Simulation, steps: usize) -> Result<(), StepError> {
    if steps == 0 {
        return Ok(());
    }
    let mut copy = sim.clone();
    match copy.advance(exec, steps) {
        Ok(()) | Err(StepError::Diverged { .. }) => Ok(()),
        Err(e) => Err(e),
    }
}

struct TracedSteps<'a> {
    sim: &'a mut Simulation,
    steps: usize,
    warmup: usize,
    recorder: &'a Recorder,
}

impl Session for TracedSteps<'_> {
    type Output = Result<(Elapsed, u64, u64), StepError>;

    fn run<E: Executor>(self, exec: &E) -> Self::Output {
        let (sim, rec) = (self.sim, self.recorder);
        warm_up(exec, sim, self.warmup)?;
        let watch = Stopwatch::start();
        let loop_start = rec.now_ns();
        for _ in 0..self.steps {
            let step = sim.steps_done + 1;
            let kernel_failed = |source| StepError::Kernel { step, source };
            let t = rec.now_ns();
            sim.rebuild_neighbors_on(&TracingExecutor::new(exec, rec, Phase::Rebuild, step))
                .map_err(kernel_failed)?;
            rec.record_serial(SerialWork::Rebuild, step, t, rec.now_ns());
            for pass in Pass::ALL {
                sim.run_pass(&TracingExecutor::new(exec, rec, pass, step), pass)
                    .map_err(kernel_failed)?;
            }
            sim.steps_done = step;
            // The same guard as `Simulation::advance`: velocities first, the full scan only
            // to name the culprit.
            let t = rec.now_ns();
            let bad = if sim.state.velocities_finite() {
                None
            } else {
                sim.state.first_non_finite()
            };
            rec.record_serial(SerialWork::Check, step, t, rec.now_ns());
            if let Some((field, particle)) = bad {
                return Err(StepError::Diverged {
                    step,
                    particle,
                    field,
                });
            }
        }
        let loop_end = rec.now_ns();
        Ok((watch.stop(), loop_start, loop_end))
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
    let workers = expected_workers(strategy, config.cores);
    let per_worker = capacity_hint(strategy, config, sim.state.len(), steps);
    let recorder = Recorder::new(workers, per_worker, 2 * steps);
    let session = TracedSteps {
        sim,
        steps,
        warmup,
        recorder: &recorder,
    };
    let result = sph_strategies::run(strategy, config, session)
        .map_err(|source| RunError::Build { strategy, source })?;
    let (elapsed, start, end) = result?;
    Ok(TracedRun {
        elapsed,
        trace: recorder.finish(start, end, workers),
    })
}

struct UntracedSteps<'a> {
    sim: &'a mut Simulation,
    steps: usize,
    warmup: usize,
}

impl Session for UntracedSteps<'_> {
    type Output = Result<Elapsed, StepError>;

    fn run<E: Executor>(self, exec: &E) -> Self::Output {
        warm_up(exec, self.sim, self.warmup)?;
        let watch = Stopwatch::start();
        self.sim.advance(exec, self.steps)?;
        Ok(watch.stop())
    }
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
    let session = UntracedSteps { sim, steps, warmup };
    let result = sph_strategies::run(strategy, config, session)
        .map_err(|source| RunError::Build { strategy, source })?;
    Ok(result?)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::checksum::checksum_hex;
    use crate::run::run_timed;
    use crate::scene::dam_break;
    use crate::sph::params::Preset;

    fn sim(n: usize) -> Simulation {
        let preset = Preset::Seed;
        Simulation::new(
            preset.params(),
            dam_break::domain(preset, n),
            dam_break::initial_state(preset, n, 7),
            NeighborMode::Grid,
        )
    }

    #[test]
    fn a_traced_run_ends_in_the_same_state_as_an_untraced_one_on_every_strategy() {
        let config = Config {
            cores: 2,
            chunks: 5,
        };
        for &strategy in StrategyName::ALL {
            let mut plain = sim(90);
            run_timed(&mut plain, strategy, &config, 3).unwrap();
            let mut traced = sim(90);
            let run = run_traced(&mut traced, strategy, &config, 3, 2).unwrap();
            assert_eq!(checksum_hex(&traced.state), checksum_hex(&plain.state));
            assert_eq!(traced.steps_done, 3, "the warm-up ran on a copy");
            let steps: Vec<usize> = run.trace.kernels.iter().map(|e| e.step).collect();
            assert_eq!(
                steps.iter().min(),
                Some(&1),
                "{strategy}: warm-up not recorded"
            );
            assert_eq!(steps.iter().max(), Some(&3), "{strategy}");
            assert_eq!(run.trace.serial.len(), 2 * 3, "{strategy}");
            assert!(
                run.trace.workers <= expected_workers(strategy, 2),
                "{strategy}"
            );
            let last = run.trace.kernels.iter().map(|e| e.end_ns).max().unwrap();
            assert!(last <= run.trace.wall_ns, "{strategy}");
        }
    }

    #[test]
    fn divergence_stops_a_traced_run_with_the_step_and_particle() {
        let mut s = sim(20);
        s.state.vx[3] = f64::NAN;
        let config = Config {
            cores: 2,
            chunks: 3,
        };
        let err = run_traced(&mut s, StrategyName::RayonChunks, &config, 5, 0).unwrap_err();
        assert!(
            matches!(err, RunError::Step(StepError::Diverged { step: 1, .. })),
            "{err}"
        );
    }
}
