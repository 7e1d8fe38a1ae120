//! How large a trace may grow. Its events are estimated before anything runs, from the
//! strategy, N, chunks, cores and steps, and a trace that would pass [`MAX_EVENTS`] is refused
//! with the estimate and what to lower: without the cap, `rayon-spawn` at N = 20 000 for 50
//! steps wrote an 824 MB `trace.json`.

use sph_strategies::{Calls, Config, StrategyName};

use sph_solver::sph::neighbors::{NeighborMode, PARALLEL_SORT};

/// The most events one trace may record (kernel calls, plus two serial events per step):
/// about 170 MB of `trace.json` at [`JSON_BYTES_PER_EVENT`], and 64 bytes an event in memory
/// (64 MB at the cap; up to about twice that while buffers grow and are merged).
pub const MAX_EVENTS: usize = 1_000_000;

/// Bytes of `trace.json` per event, roughly (measured: 155 to 175), for the estimate in the
/// refusal message.
pub const JSON_BYTES_PER_EVENT: usize = 170;

/// The leaves per worker that the estimate assumes for `rayon-iter`, the one strategy whose
/// splitting rayon decides at run time ([`Calls::Adaptive`]): a few per thread on an idle
/// pool, more after steals (observed: 5 per core per pass at 2 cores, 100 to 165 at 8 cores
/// on 2 hardware threads), never more than N.
/// A run that records more than [`MAX_EVENTS`] anyway is refused before it writes
/// ([`check_recorded`]).
pub const RAYON_ITER_LEAVES_PER_CORE: usize = 128;

/// What a trace would record.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Plan {
    /// The strategy.
    pub strategy: StrategyName,
    /// Particles.
    pub n: usize,
    /// Requested chunks per pass (ignored by strategies that do not use chunks).
    pub chunks: usize,
    /// Worker threads.
    pub cores: usize,
    /// Recorded steps.
    pub steps: usize,
    /// The model's passes per step (2 for Müller's presets, 6 for `wcsph`).
    pub passes: usize,
    /// Neighbour search: the grid's rebuild adds two kernel calls per step and chunk, three
    /// from [`PARALLEL_SORT`] particles on (counted whatever the cores: an upper bound).
    pub neighbors: NeighborMode,
}

/// A trace over [`MAX_EVENTS`].
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error(
    "a trace of {strategy} with N = {n} over {steps} steps would record about {events} events \
     (about {mb} MB of trace.json); the most is {max}: lower {lower}",
    strategy = .plan.strategy,
    n = .plan.n,
    steps = .plan.steps,
    mb = .events.saturating_mul(JSON_BYTES_PER_EVENT) / 1_000_000,
    max = MAX_EVENTS,
    lower = lower(.plan.strategy)
)]
pub struct TooLarge {
    /// What was asked for.
    pub plan: Plan,
    /// Its estimated events.
    pub events: usize,
}

/// A run that recorded more than [`MAX_EVENTS`] although its estimate was below (possible
/// only where the strategy decides its own splitting: `rayon-iter`).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error(
    "the trace recorded {events} events, more than the most ({max}), so nothing was written: \
     lower {lower}",
    max = MAX_EVENTS,
    lower = lower(*.strategy)
)]
pub struct RecordedTooMany {
    /// The strategy.
    pub strategy: StrategyName,
    /// The events recorded.
    pub events: usize,
}

/// `Ok` if a run of `strategy` recorded at most [`MAX_EVENTS`] events.
pub fn check_recorded(strategy: StrategyName, events: usize) -> Result<(), RecordedTooMany> {
    if events > MAX_EVENTS {
        return Err(RecordedTooMany { strategy, events });
    }
    Ok(())
}

/// The options that shrink a trace of `strategy`: those its kernel calls per pass grow with.
fn lower(strategy: StrategyName) -> String {
    match strategy.info().calls {
        Calls::Whole => "--steps".to_owned(),
        Calls::Elements => {
            format!("--steps or --n ({strategy} records one event per particle and pass)")
        }
        Calls::Chunks => "--steps or --chunks".to_owned(),
        Calls::Blocks | Calls::Adaptive => "--steps or --cores".to_owned(),
    }
}

impl Plan {
    /// Kernel calls in one pass: what the strategy's registry entry promises
    /// ([`sph_strategies::Info::kernel_calls`]), and where the runtime decides (`rayon-iter`)
    /// min([`RAYON_ITER_LEAVES_PER_CORE`] × cores, N).
    pub fn calls_per_pass(&self) -> usize {
        let config = Config::new(self.cores, self.chunks);
        let n = self.n;
        self.strategy
            .info()
            .kernel_calls(n, &config)
            .unwrap_or_else(|| RAYON_ITER_LEAVES_PER_CORE.saturating_mul(self.cores).min(n))
    }

    /// Passes that call kernels per step: the model's passes, and the grid rebuild's two, or
    /// three where it may sort in bands (see [`PARALLEL_SORT`]).
    pub fn kernel_passes_per_step(&self) -> usize {
        match self.neighbors {
            NeighborMode::AllPairs => self.passes,
            NeighborMode::Grid if self.n >= PARALLEL_SORT => self.passes + 3,
            NeighborMode::Grid => self.passes + 2,
        }
    }

    /// The kernel calls of the whole trace.
    pub fn kernel_calls(&self) -> usize {
        self.calls_per_pass()
            .saturating_mul(self.kernel_passes_per_step())
            .saturating_mul(self.steps)
    }

    /// The events of the whole trace: kernel calls and two serial events per step.
    pub fn events(&self) -> usize {
        self.kernel_calls()
            .saturating_add(self.steps.saturating_mul(2))
    }

    /// The estimated events, or [`TooLarge`] above [`MAX_EVENTS`].
    pub fn check(&self) -> Result<usize, TooLarge> {
        let events = self.events();
        if events > MAX_EVENTS {
            return Err(TooLarge {
                plan: *self,
                events,
            });
        }
        Ok(events)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn plan(strategy: StrategyName, n: usize, steps: usize) -> Plan {
        Plan {
            strategy,
            n,
            chunks: 45,
            cores: 2,
            steps,
            passes: 2,
            neighbors: NeighborMode::AllPairs,
        }
    }

    #[test]
    fn the_estimate_counts_one_event_per_kernel_call_and_two_per_step() {
        assert_eq!(
            plan(StrategyName::RayonChunks, 1000, 5).events(),
            45 * 2 * 5 + 10
        );
        assert_eq!(plan(StrategyName::RayonChunks, 20, 5).calls_per_pass(), 20);
        assert_eq!(
            plan(StrategyName::RayonSpawn, 1000, 5).kernel_calls(),
            10_000
        );
        assert_eq!(plan(StrategyName::StdStatic, 1000, 1).calls_per_pass(), 2);
        assert_eq!(plan(StrategyName::Seq, 1000, 1).calls_per_pass(), 1);
        let grid = Plan {
            neighbors: NeighborMode::Grid,
            ..plan(StrategyName::RayonChunks, 1000, 1)
        };
        assert_eq!(grid.kernel_calls(), 45 * 4);
    }

    #[test]
    fn rayon_spawn_at_twenty_thousand_particles_for_fifty_steps_is_refused_naming_the_estimate() {
        let err = plan(StrategyName::RayonSpawn, 20_000, 50)
            .check()
            .unwrap_err();
        assert_eq!(
            err.to_string(),
            "a trace of rayon-spawn with N = 20000 over 50 steps would record about 2000100 \
             events (about 340 MB of trace.json); the most is 1000000: lower --steps or --n \
             (rayon-spawn records one event per particle and pass)"
        );
        assert!(plan(StrategyName::RayonSpawn, 1000, 5).check().is_ok());
    }

    #[test]
    fn a_run_that_recorded_more_than_the_cap_is_refused_before_writing() {
        assert!(check_recorded(StrategyName::RayonIter, MAX_EVENTS).is_ok());
        let err = check_recorded(StrategyName::RayonIter, MAX_EVENTS + 1).unwrap_err();
        assert!(
            err.to_string()
                .contains("nothing was written: lower --steps or --cores")
        );
    }

    #[test]
    fn the_largest_counts_saturate_instead_of_overflowing() {
        let p = Plan {
            cores: crate::limits::MAX_CORES,
            ..plan(
                StrategyName::RayonSpawn,
                crate::limits::MAX_PARTICLES,
                usize::MAX,
            )
        };
        assert_eq!(p.events(), usize::MAX);
        assert!(p.check().is_err());
    }
}
