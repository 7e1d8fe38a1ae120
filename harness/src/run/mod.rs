//! A run: the step loop of a [`Simulation`] inside one session of a named strategy, timed.
//!
//! The timed region is the step loop only (grid rebuilds, spawns, barriers and the divergence
//! check included); building the initial state and the thread pool, waking its threads
//! (`sph_strategies::wake`), warm-up steps, the checksum and the dump are outside it. CPU
//! time is the process's user + system time over the same window. A run cut into segments ([`Steps::every`], for frames) times each segment on
//! its own and shows the simulation to an [`Observer`] between them, outside the timing; all
//! segments run in the one session, on the one pool.

#[cfg(feature = "testing")]
pub mod fault;
pub mod paired;
pub mod pass_cost;

use std::ops::ControlFlow;

use sph_strategies::{Config, Executor, Session, StrategyName};

use crate::clock::{Elapsed, Stopwatch};
use crate::placement::Pinned;
use sph_solver::solver::{Simulation, StepError, StepHooks};

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
    /// The run's threads could not be placed as `--pin` asked (see [`crate::placement`]).
    #[error("{0:#}")]
    Placement(anyhow::Error),
}

/// How a run lays out its steps.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Steps {
    /// Steps to run (after the warm-up).
    pub total: usize,
    /// Steps per timed segment: the observer sees the simulation after each (`>= 1`).
    pub every: usize,
    /// Untimed steps first, on a copy of the simulation that is then discarded: they wake
    /// the strategy's threads and leave the timed steps those of a run without warm-up. A
    /// copy that diverges (or leaves its model) only ends the warm-up; a kernel's panic is an error.
    pub warmup: usize,
    /// Simulated time at which the run ends early, s: it stops after the first step that
    /// reaches it (`total` then only caps the steps). `None`: run `total` steps.
    pub until_s: Option<f64>,
}

impl Steps {
    /// `total` steps timed as one segment, without warm-up.
    pub fn timed(total: usize) -> Steps {
        Steps {
            total,
            every: total,
            warmup: 0,
            until_s: None,
        }
    }
}

/// Sees the simulation after each timed segment of a run, on the session's thread and outside
/// the timing.
pub trait Observer: Send {
    /// Called with the simulation after a segment and the time its steps took; `Break` ends
    /// the run there (successfully).
    fn segment(&mut self, sim: &Simulation, elapsed: Elapsed) -> ControlFlow<()>;
}

/// No observer.
impl Observer for () {
    fn segment(&mut self, _: &Simulation, _: Elapsed) -> ControlFlow<()> {
        ControlFlow::Continue(())
    }
}

/// Keeps the time of the last segment: the whole run's, for a run of one segment.
struct LastSegment(Option<Elapsed>);

impl Observer for LastSegment {
    fn segment(&mut self, _: &Simulation, elapsed: Elapsed) -> ControlFlow<()> {
        self.0 = Some(elapsed);
        ControlFlow::Continue(())
    }
}

/// The session of a run. Generic over the hooks only, which are the harness's own (none, the
/// trace's, the injected fault's): every public function of this module is monomorphic, so the
/// solver is compiled for each strategy's executor here, once, and not again in every crate
/// that runs a simulation (a release build does not share generic instances between crates).
struct Segments<'a, H> {
    sim: &'a mut Simulation,
    /// The CPUs the strategy's threads may use (see [`sph_strategies::wake()`]).
    cpus: usize,
    steps: Steps,
    hooks: &'a mut H,
    observer: &'a mut dyn Observer,
}

impl<H: StepHooks + Send> Session for Segments<'_, H> {
    type Output = Result<(), StepError>;

    fn run<E: Executor>(self, exec: &E) -> Self::Output {
        let Steps {
            total,
            every,
            warmup,
            until_s,
        } = self.steps;
        wake_threads(exec, self.cpus, self.sim.steps_done)?;
        if warmup > 0 {
            match self.sim.clone().advance(exec, warmup) {
                Ok(()) | Err(StepError::Diverged { .. } | StepError::Unphysical { .. }) => {}
                Err(e) => return Err(e),
            }
        }
        let mut done = 0;
        while done < total {
            let steps = every.max(1).min(total - done);
            let watch = Stopwatch::start();
            let ran = match until_s {
                None => self
                    .sim
                    .advance_with(exec, steps, self.hooks)
                    .map(|()| steps),
                Some(t) => self.sim.advance_until(exec, steps, t, self.hooks),
            }?;
            let elapsed = watch.stop();
            done += ran;
            let reached = until_s.is_some_and(|t| self.sim.time_s >= t);
            if self.observer.segment(self.sim, elapsed).is_break() || reached {
                break;
            }
        }
        Ok(())
    }
}

/// Runs `steps` of `sim` in one session of `strategy`, showing the simulation to `observer`
/// after every segment. With a placement other than the operating system's, the calling
/// thread is pinned for the run too ([`Pinned`]). Before its steps (and its warm-up) the
/// session wakes the strategy's threads ([`sph_strategies::wake()`]): untimed passes that spin
/// until the threads run on their cores, at most 0.15 s.
pub fn run_steps(
    sim: &mut Simulation,
    strategy: StrategyName,
    config: &Config,
    steps: Steps,
    observer: &mut dyn Observer,
) -> Result<(), RunError> {
    run_steps_with(sim, strategy, config, steps, &mut (), observer)
}

/// [`run_steps`] with each phase and check through `hooks`.
fn run_steps_with<H: StepHooks + Send>(
    sim: &mut Simulation,
    strategy: StrategyName,
    config: &Config,
    steps: Steps,
    hooks: &mut H,
    observer: &mut dyn Observer,
) -> Result<(), RunError> {
    let session = Segments {
        sim,
        // Read before the caller is pinned (a pinned caller may run on one CPU only).
        cpus: config.placement.parallelism(),
        steps,
        hooks,
        observer,
    };
    Ok(in_session(strategy, config, session)??)
}

/// Runs `session` in one session of `strategy`, the calling thread pinned for it as
/// `config`'s placement asks ([`Pinned`]).
fn in_session<S: Session>(
    strategy: StrategyName,
    config: &Config,
    session: S,
) -> Result<S::Output, RunError> {
    let pinned = Pinned::caller(config.placement).map_err(RunError::Placement)?;
    let result = sph_strategies::run(strategy, config, session)
        .map_err(|source| RunError::Build { strategy, source })?;
    pinned.finish().map_err(RunError::Placement)?;
    Ok(result)
}

/// Wakes `exec`'s threads on `cpus` CPUs ([`sph_strategies::wake()`]) before step `step`.
fn wake_threads<E: Executor>(exec: &E, cpus: usize, step: usize) -> Result<(), StepError> {
    sph_strategies::wake(exec, cpus)
        .map(|_| ())
        .map_err(|source| StepError::Kernel { step, source })
}

/// Runs `warmup` untimed steps on a copy of `sim` (see [`Steps::warmup`]), then `steps` steps
/// of `sim` with `strategy`, each phase and check through `hooks`, and returns the time the
/// `steps` took (zero for zero steps).
pub(crate) fn run_timed_with<H: StepHooks + Send>(
    sim: &mut Simulation,
    strategy: StrategyName,
    config: &Config,
    steps: usize,
    warmup: usize,
    hooks: &mut H,
) -> Result<Elapsed, RunError> {
    let steps = Steps {
        warmup,
        ..Steps::timed(steps)
    };
    run_timed_steps_with(sim, strategy, config, steps, hooks)
}

/// Runs `steps` of `sim` with `strategy` as one timed segment (`steps.every` is ignored) and
/// returns the time they took (zero for none).
pub fn run_timed_steps(
    sim: &mut Simulation,
    strategy: StrategyName,
    config: &Config,
    steps: Steps,
) -> Result<Elapsed, RunError> {
    run_timed_steps_with(sim, strategy, config, steps, &mut ())
}

/// [`run_timed_steps`] with each phase and check through `hooks`.
pub(crate) fn run_timed_steps_with<H: StepHooks + Send>(
    sim: &mut Simulation,
    strategy: StrategyName,
    config: &Config,
    steps: Steps,
    hooks: &mut H,
) -> Result<Elapsed, RunError> {
    let steps = Steps {
        every: steps.total,
        ..steps
    };
    let mut last = LastSegment(None);
    run_steps_with(sim, strategy, config, steps, hooks, &mut last)?;
    Ok(last.0.unwrap_or(Elapsed {
        wall_s: 0.0,
        cpu_s: 0.0,
        foreign: None,
    }))
}

/// Runs `steps` steps of `sim` with `strategy` and returns the time they took.
pub fn run_timed(
    sim: &mut Simulation,
    strategy: StrategyName,
    config: &Config,
    steps: usize,
) -> Result<Elapsed, RunError> {
    run_timed_with(sim, strategy, config, steps, 0, &mut ())
}

/// `steps` steps of `sim` in one session of `strategy` (placed as `config` asks), and nothing
/// else around them: no wake of the threads, no timing. What the tests' strategy matrix runs
/// (thousands of short runs, for which the wake's spinning would be most of the time); the
/// solver's code is the same that every run steps with, compiled here once.
#[cfg(feature = "testing")]
pub fn run_steps_only(
    sim: &mut Simulation,
    strategy: StrategyName,
    config: &Config,
    steps: usize,
) -> Result<(), RunError> {
    struct Advance<'a>(&'a mut Simulation, usize);
    impl Session for Advance<'_> {
        type Output = Result<(), StepError>;
        fn run<E: Executor>(self, exec: &E) -> Self::Output {
            self.0.advance(exec, self.1)
        }
    }
    Ok(in_session(strategy, config, Advance(sim, steps))??)
}

/// The seed preset's dam break of `n` particles (jitter seed `seed`) with the grid search:
/// the simulation that the unit tests above the solver run.
#[cfg(any(test, feature = "testing"))]
pub fn test_simulation(n: usize, seed: u64) -> Simulation {
    use sph_solver::models::mueller::scene;
    let preset = sph_solver::models::Preset::Seed;
    Simulation::new(
        preset.params(),
        scene::domain(preset, n),
        scene::initial_state(preset, n, seed),
        sph_solver::sph::neighbors::NeighborMode::Grid,
    )
}

#[cfg(test)]
mod tests {
    use std::thread::ThreadId;

    use super::*;
    use sph_solver::checksum::checksum_hex;

    fn sim(n: usize) -> Simulation {
        test_simulation(n, 7)
    }

    const CONFIG: Config = Config::new(2, 5);

    /// Notes the step and the thread of every segment, and stops after `stop_after`.
    struct Seen {
        steps: Vec<usize>,
        threads: Vec<ThreadId>,
        stop_after: usize,
    }

    impl Observer for Seen {
        fn segment(&mut self, sim: &Simulation, _: Elapsed) -> ControlFlow<()> {
            self.steps.push(sim.steps_done);
            self.threads.push(std::thread::current().id());
            if self.steps.len() == self.stop_after {
                ControlFlow::Break(())
            } else {
                ControlFlow::Continue(())
            }
        }
    }

    fn seen(stop_after: usize) -> Seen {
        Seen {
            steps: Vec::new(),
            threads: Vec::new(),
            stop_after,
        }
    }

    #[test]
    fn a_run_in_segments_shows_every_segment_in_one_session_and_ends_as_one_run() {
        for &strategy in StrategyName::ALL {
            let mut whole = sim(60);
            run_timed(&mut whole, strategy, &CONFIG, 7).unwrap();
            let mut cut = sim(60);
            let steps = Steps {
                every: 3,
                ..Steps::timed(7)
            };
            let mut observer = seen(usize::MAX);
            run_steps(&mut cut, strategy, &CONFIG, steps, &mut observer).unwrap();
            assert_eq!(observer.steps, [3, 6, 7], "{strategy}");
            let first = observer.threads[0];
            assert!(
                observer.threads.iter().all(|&t| t == first),
                "{strategy}: one session runs every segment on the same thread"
            );
            assert_eq!(checksum_hex(&cut.state), checksum_hex(&whole.state));
        }
    }

    #[test]
    fn a_run_until_a_time_stops_after_the_first_step_that_reaches_it() {
        let mut s = sim(40);
        let dt = s.last_dt();
        let steps = Steps {
            until_s: Some(10.5 * dt),
            ..Steps::timed(1000)
        };
        run_timed_steps(&mut s, StrategyName::Seq, &CONFIG, steps).unwrap();
        assert_eq!(s.steps_done, 11);
        assert!(s.time_s >= 10.5 * dt && s.time_s < 11.5 * dt);
        // The step cap still holds.
        let mut capped = sim(40);
        let steps = Steps {
            until_s: Some(1.0),
            ..Steps::timed(4)
        };
        run_timed_steps(&mut capped, StrategyName::Seq, &CONFIG, steps).unwrap();
        assert_eq!(capped.steps_done, 4);
    }

    #[test]
    fn an_observer_that_breaks_ends_the_run_there_without_an_error() {
        let mut s = sim(40);
        let steps = Steps {
            every: 2,
            ..Steps::timed(usize::MAX)
        };
        let mut observer = seen(3);
        run_steps(&mut s, StrategyName::Seq, &CONFIG, steps, &mut observer).unwrap();
        assert_eq!((observer.steps, s.steps_done), (vec![2, 4, 6], 6));
    }

    #[test]
    fn warm_up_steps_run_on_a_copy_and_leave_the_timed_steps_unchanged() {
        let mut plain = sim(40);
        run_timed(&mut plain, StrategyName::RayonChunks, &CONFIG, 4).unwrap();
        let mut warmed = sim(40);
        run_timed_with(
            &mut warmed,
            StrategyName::RayonChunks,
            &CONFIG,
            4,
            3,
            &mut (),
        )
        .unwrap();
        assert_eq!(warmed.steps_done, 4);
        assert_eq!(checksum_hex(&warmed.state), checksum_hex(&plain.state));
    }
}
