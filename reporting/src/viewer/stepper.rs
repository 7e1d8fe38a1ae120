//! The viewer's simulation, stepping in one session of its strategy (one thread pool) for as
//! long as the strategy stays the same, on a thread of its own so that the window stays on
//! the main thread.
//!
//! The two threads go in lockstep: [`Stepper::advance`] asks for the next `every` steps and
//! waits for them, and the run's [`Observer`] hands back a copy of the state after them, then
//! waits for the next request. Nothing steps while the viewer does not ask (a paused scene
//! stays where it is); dropping the request channel ends the session, and the simulation
//! comes back with the thread's result.

use std::ops::ControlFlow;
use std::sync::mpsc::{Receiver, SyncSender, sync_channel};
use std::thread::JoinHandle;

use sph_strategies::{BuildError, Config, StrategyName};

use sph_harness::clock::Elapsed;
use sph_harness::run::{Observer, RunError, Steps, run_steps};
use sph_solver::solver::Simulation;
use sph_solver::sph::state::State;

/// What the observer hands back after each segment: the state, its step, the simulated time
/// and the wall time of the segment, s.
type Segment = (State, usize, f64, f64);

/// A session in progress on its own thread, which gives the simulation back when it ends.
struct Session {
    /// Asks for the next segment; dropped to end the session.
    ask: SyncSender<()>,
    done: Receiver<Segment>,
    thread: JoinHandle<(Simulation, Result<(), RunError>)>,
}

/// A simulation that steps `every` steps at a time on one strategy, in one session.
pub struct Stepper {
    strategy: StrategyName,
    config: Config,
    every: usize,
    /// The simulation while no session holds it.
    idle: Option<Simulation>,
    session: Option<Session>,
    /// The state after the last segment, its step and its simulated time, s.
    shown: (State, usize, f64),
}

/// The run's observer: sends each segment's state and waits for the next request.
struct Relay {
    ask: Receiver<()>,
    done: SyncSender<Segment>,
}

impl Observer for Relay {
    fn segment(&mut self, sim: &Simulation, elapsed: Elapsed) -> ControlFlow<()> {
        let segment = (
            sim.state.clone(),
            sim.steps_done,
            sim.time_s,
            elapsed.wall_s,
        );
        if self.done.send(segment).is_ok() && self.ask.recv().is_ok() {
            ControlFlow::Continue(())
        } else {
            ControlFlow::Break(())
        }
    }
}

impl Stepper {
    /// `sim`, to be stepped `every` steps at a time on `strategy` (nothing runs yet).
    pub fn new(sim: Simulation, strategy: StrategyName, config: Config, every: usize) -> Self {
        Stepper {
            strategy,
            config,
            every,
            shown: (sim.state.clone(), sim.steps_done, sim.time_s),
            idle: Some(sim),
            session: None,
        }
    }

    /// The state after the last step, and the steps done.
    pub fn shown(&self) -> (&State, usize) {
        (&self.shown.0, self.shown.1)
    }

    /// The simulated time of the state shown, s.
    pub fn shown_time_s(&self) -> f64 {
        self.shown.2
    }

    /// Runs the next `every` steps and returns their wall time, s. After an error the state
    /// shown is the one the failing step left, and the next call starts a new session.
    pub fn advance(&mut self) -> Result<f64, RunError> {
        let asked = match (&self.session, self.idle.take()) {
            (Some(session), _) => session.ask.send(()).is_ok(),
            (None, Some(sim)) => {
                self.start(sim)?;
                true
            }
            (None, None) => unreachable!("the simulation is idle or in a session"),
        };
        let segment = match &self.session {
            Some(session) if asked => session.done.recv().ok(),
            _ => None,
        };
        match segment {
            Some((state, steps_done, time_s, wall_s)) => {
                self.shown = (state, steps_done, time_s);
                Ok(wall_s)
            }
            None => self.end(),
        }
    }

    /// Goes on with `strategy`: ends the session, if one runs (the next [`Stepper::advance`]
    /// starts one on the new strategy's threads).
    pub fn switch_to(&mut self, strategy: StrategyName) {
        // A session that ended by itself reported its error to `advance` already.
        let _ = self.end();
        self.strategy = strategy;
    }

    /// Starts a session on a thread of its own; its first segment runs at once. If the thread
    /// cannot start, the simulation stays idle.
    fn start(&mut self, sim: Simulation) -> Result<(), RunError> {
        let (ask, ask_rx) = sync_channel(1);
        let (done_tx, done) = sync_channel(1);
        let (give, take) = sync_channel::<Simulation>(1);
        let (strategy, config) = (self.strategy, self.config);
        let steps = Steps {
            total: usize::MAX,
            every: self.every,
            warmup: 0,
            until_s: None,
        };
        let spawned = std::thread::Builder::new()
            .name("viewer steps".into())
            .spawn(move || {
                let mut sim = take.recv().expect("the simulation is sent after the spawn");
                let mut relay = Relay {
                    ask: ask_rx,
                    done: done_tx,
                };
                let result = run_steps(&mut sim, strategy, &config, steps, &mut relay);
                (sim, result)
            });
        let thread = match spawned {
            Ok(thread) => thread,
            Err(source) => {
                self.idle = Some(sim);
                let source = BuildError::ThreadStart {
                    thread: 1,
                    threads: 1,
                    source,
                };
                return Err(RunError::Build { strategy, source });
            }
        };
        give.send(sim)
            .expect("the new thread waits for the simulation");
        self.session = Some(Session { ask, done, thread });
        Ok(())
    }

    /// Ends the session, if one runs: takes the simulation back (and shows its state) and
    /// returns how the run ended.
    fn end(&mut self) -> Result<f64, RunError> {
        let Some(session) = self.session.take() else {
            return Ok(0.0);
        };
        drop(session.ask);
        let (sim, result) = session
            .thread
            .join()
            .unwrap_or_else(|panic| std::panic::resume_unwind(panic));
        self.shown = (sim.state.clone(), sim.steps_done, sim.time_s);
        self.idle = Some(sim);
        result.map(|()| 0.0)
    }
}

impl Drop for Stepper {
    fn drop(&mut self) {
        let _ = self.end();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use sph_solver::solver::StepError;

    fn sim(n: usize) -> Simulation {
        sph_harness::run::test_simulation(n, 3)
    }

    const CONFIG: Config = Config::new(2, 3);

    #[test]
    fn a_stepper_gives_the_bits_of_one_plain_run_across_segments_and_strategy_switches() {
        let mut plain = sim(50);
        sph_harness::run::run_timed(&mut plain, StrategyName::Seq, &CONFIG, 12).unwrap();
        let mut stepper = Stepper::new(sim(50), StrategyName::RayonChunks, CONFIG, 3);
        assert_eq!(
            stepper.shown().1,
            0,
            "nothing runs before the first request"
        );
        for strategy in [StrategyName::CrossbeamPool, StrategyName::StdStatic] {
            stepper.advance().unwrap();
            stepper.switch_to(strategy);
        }
        stepper.advance().unwrap();
        stepper.advance().unwrap();
        let (state, steps) = stepper.shown();
        assert_eq!(steps, 12);
        assert_eq!(state, &plain.state);
    }

    #[test]
    fn a_failing_step_is_an_error_and_its_state_is_the_one_shown() {
        let mut s = sim(30);
        s.state.vx[4] = f64::NAN;
        let mut stepper = Stepper::new(s, StrategyName::RayonChunks, CONFIG, 5);
        let err = stepper.advance().unwrap_err();
        assert!(
            matches!(err, RunError::Step(StepError::Diverged { step: 1, .. })),
            "{err}"
        );
        let (state, steps) = stepper.shown();
        assert_eq!(steps, 1);
        assert!(!state.velocities_finite());
    }
}
