//! A strategy and `seq` stepped in turn, one step each, in one session: a speedup measured on
//! a machine whose speed drifts.
//!
//! On a shared virtual machine the same run takes 0.7 s one second and 1.1 s the next
//! (`seq` at N = 10⁶, 10 steps, minutes apart on the project's 2-core VM). Separate runs of
//! `seq` and of a parallel strategy then land in different moments, and their ratio says as
//! much about the moments as about the strategy: over seven rounds of such runs, one round's
//! efficiency ranged from 0.64 to 1.48. Here the two copies of one simulation take turns a step at a
//! time (which one goes first alternating), so a slow moment slows both, and each step gives
//! its own ratio. Both copies run the same steps from the same state, and must end with the
//! same bits.

use std::time::Instant;

use sph_strategies::seq::SeqExecutor;
use sph_strategies::{Config, Executor, Info, Session, StrategyName, rouse};

use super::RunError;
use sph_solver::solver::{Simulation, StepError};

/// Step times of the two copies, in seconds, step by step.
#[derive(Debug, Clone, PartialEq)]
pub struct PairedTimes {
    /// `seq`'s time of each step.
    pub seq_s: Vec<f64>,
    /// The strategy's time of each step.
    pub strategy_s: Vec<f64>,
}

/// Runs `steps` steps of `seq_sim` on the session's thread alone and of `sim` with
/// `strategy`, in turn, in one session of `strategy` (its threads woken first, as every run's:
/// see [`super::run_steps`]). Stops at the first failing step of either, and says which copy
/// failed.
///
/// The strategy's threads fall asleep while `seq` steps, and waking them costs tens of
/// microseconds on a quiet machine (more on a virtual one), which a run of the strategy alone,
/// its passes back to back, does not pay. So before each of its steps, untimed, the
/// strategy's threads are roused ([`sph_strategies::rouse`]): its steps begin as they do in a
/// run of their own, where the serial work between steps is shorter than the threads' watch
/// (at N = 10⁶ a run of its own may find them asleep, and the rouse spares it that cost). At
/// the paper's workload on the project's 2-core VM, with the threads left asleep,
/// `crossbeam-pool` measured 1.47× here where its runs alone were 1.78× faster than `seq`'s.
pub fn run_paired(
    seq_sim: &mut Simulation,
    sim: &mut Simulation,
    strategy: StrategyName,
    config: &Config,
    steps: usize,
) -> anyhow::Result<PairedTimes> {
    let session = Paired {
        seq_sim,
        sim,
        steps,
        cpus: config.placement.parallelism(),
        info: strategy.info(),
        config: *config,
    };
    super::in_session(strategy, config, session)?.map_err(|(copy, source)| {
        let copy = copy.unwrap_or(strategy.info().name);
        anyhow::Error::new(RunError::Step(source)).context(format!("the {copy} copy"))
    })
}

struct Paired<'a> {
    seq_sim: &'a mut Simulation,
    sim: &'a mut Simulation,
    steps: usize,
    cpus: usize,
    info: Info,
    config: Config,
}

/// Which copy failed: `Some("seq")`, or `None` for the strategy's.
type Copy = Option<&'static str>;

impl Session for Paired<'_> {
    type Output = Result<PairedTimes, (Copy, StepError)>;

    fn run<E: Executor>(self, exec: &E) -> Self::Output {
        let seq = |e| (Some("seq"), e);
        let strategy = |e| (None, e);
        super::wake_threads(exec, self.cpus, self.sim.steps_done).map_err(strategy)?;
        let mut times = PairedTimes {
            seq_s: Vec::with_capacity(self.steps),
            strategy_s: Vec::with_capacity(self.steps),
        };
        for step in 0..self.steps {
            let seq_first = step % 2 == 0;
            if seq_first {
                times
                    .seq_s
                    .push(timed(|| self.seq_sim.advance(&SeqExecutor, 1)).map_err(seq)?);
            }
            // Whether every thread came in time is not needed: a late one is still waking, as
            // it would be without the rouse.
            let next = self.sim.steps_done + 1;
            rouse(exec, &self.info, &self.config)
                .map_err(|source| strategy(StepError::Kernel { step: next, source }))?;
            times
                .strategy_s
                .push(timed(|| self.sim.advance(exec, 1)).map_err(strategy)?);
            if !seq_first {
                times
                    .seq_s
                    .push(timed(|| self.seq_sim.advance(&SeqExecutor, 1)).map_err(seq)?);
            }
        }
        Ok(times)
    }
}

/// The wall time of `step`, in seconds, or its error.
fn timed(step: impl FnOnce() -> Result<(), StepError>) -> Result<f64, StepError> {
    let start = Instant::now();
    step()?;
    Ok(start.elapsed().as_secs_f64())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::run::test_simulation;
    use sph_solver::checksum::checksum_hex;

    #[test]
    fn both_copies_run_every_step_and_end_with_the_bits_of_a_plain_run() {
        let mut plain = test_simulation(300, 4);
        plain.advance(&SeqExecutor, 7).unwrap();
        let (mut seq_sim, mut sim) = (test_simulation(300, 4), test_simulation(300, 4));
        let config = Config::new(2, 5);
        let times = run_paired(
            &mut seq_sim,
            &mut sim,
            StrategyName::CrossbeamPool,
            &config,
            7,
        )
        .unwrap();
        assert_eq!((times.seq_s.len(), times.strategy_s.len()), (7, 7));
        assert!(
            times
                .seq_s
                .iter()
                .chain(&times.strategy_s)
                .all(|&t| t > 0.0)
        );
        assert_eq!((seq_sim.steps_done, sim.steps_done), (7, 7));
        assert_eq!(checksum_hex(&seq_sim.state), checksum_hex(&plain.state));
        assert_eq!(checksum_hex(&sim.state), checksum_hex(&plain.state));
    }
}
