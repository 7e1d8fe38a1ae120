//! What a pass costs a strategy apart from its work (`bench-sph overhead`,
//! `benches/overhead.rs`).
//!
//! A pass here has a known amount of work and nothing else: its output is [`PER_CORE`]
//! `u64`s a thread, cut into one chunk a thread (`--chunks` = cores, the least a chunked
//! strategy can be given), and each element's kernel call keeps its thread busy for its
//! share of the work (a clock loop) before it writes the element's index. A pass with `work`
//! a thread then ends in `work` only if every thread takes its share at once; what it takes
//! beyond that is the strategy's cost of forking, handing out and joining the pass (with its
//! kernel calls: `rayon-spawn` makes one per element), and a strategy that leaves a thread
//! idle shows it as up to `work` more. With no work at all, the forking thread may finish
//! every chunk before another takes one, and the pass measures only the floor.

use std::hint::black_box;
use std::time::{Duration, Instant};

use anyhow::Context;
use serde::{Deserialize, Serialize};
use sph_strategies::{Config, Executor, KernelPanic, Session, StrategyName};

use crate::results::intervals::ratio;

/// Elements of a pass's output per thread: two cache lines each.
pub const PER_CORE: usize = 16;

/// Runs `passes` passes over `out`, each element's kernel call busy for `busy`, and returns
/// the time they took.
pub fn busy_passes<E: Executor>(
    exec: &E,
    out: &mut [u64],
    passes: u64,
    busy: Duration,
) -> Result<Duration, KernelPanic> {
    let begin = Instant::now();
    for _ in 0..passes {
        exec.for_each_chunk(&mut *out, |first, chunk: &mut [u64]| {
            let start = Instant::now();
            let until = busy.saturating_mul(u32::try_from(chunk.len()).unwrap_or(u32::MAX));
            while start.elapsed() < until {
                std::hint::spin_loop();
            }
            for (k, x) in chunk.iter_mut().enumerate() {
                *x = (first + k) as u64;
            }
        })?;
    }
    let elapsed = begin.elapsed();
    black_box(out);
    Ok(elapsed)
}

/// The output and the work a pass of `cores` threads needs for `work` a thread: `cores` ×
/// [`PER_CORE`] elements, each busy for `work / PER_CORE`.
pub fn pass_of(cores: usize, work: Duration) -> (Vec<u64>, Duration) {
    let per_element = work / u32::try_from(PER_CORE).unwrap_or(u32::MAX);
    (vec![0; cores * PER_CORE], per_element)
}

/// Times `rounds` rounds of `passes` passes with `work` a thread, on `strategy` with `cores`
/// threads and one chunk a thread, in one session of it (its threads started and woken first,
/// as in a run), and returns each round's mean time per pass, in seconds.
pub fn measure(
    strategy: StrategyName,
    cores: usize,
    work: Duration,
    passes: u64,
    rounds: usize,
) -> anyhow::Result<Vec<f64>> {
    let config = Config::new(cores, cores);
    let session = Rounds {
        cores,
        work,
        passes,
        rounds,
    };
    Ok(super::in_session(strategy, &config, session)??)
}

/// `pass-cost.csv`'s header: [`CostRow`]'s fields.
pub const PASS_COST_COLUMNS: [&str; 8] = [
    "strategy",
    "cores",
    "work_us",
    "pass_us",
    "pass_low_us",
    "pass_high_us",
    "beyond_work_us",
    "oversubscribed",
];

/// One strategy's pass at one core count: a line of `bench-sph overhead` and a row of a
/// sweep's `pass-cost.csv` ([`crate::results::PASS_COST_FILE`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CostRow {
    /// The strategy's name.
    pub strategy: String,
    /// Its worker threads (one chunk each).
    pub cores: usize,
    /// The work of a pass per thread, µs.
    pub work_us: f64,
    /// Typical time a pass, µs: the geometric mean of the rounds' mean times a pass (as a
    /// sweep's cell times), and its 95 % interval.
    pub pass_us: f64,
    /// The interval's low end, µs.
    pub pass_low_us: f64,
    /// The interval's high end, µs.
    pub pass_high_us: f64,
    /// `pass_us` less the work a thread: the strategy's cost a pass.
    pub beyond_work_us: f64,
    /// More threads than the machine's hardware threads.
    pub oversubscribed: bool,
}

impl CostRow {
    /// What makes the row impossible, if anything: no threads, or a time that is not finite
    /// and positive, or an interval that does not hold its centre.
    pub fn problem(&self) -> Option<String> {
        let times = [self.pass_us, self.pass_low_us, self.pass_high_us];
        if self.cores == 0 {
            return Some("0 cores".into());
        }
        if !(self.work_us.is_finite() && self.work_us >= 0.0) {
            return Some(format!("work {} µs", self.work_us));
        }
        if times.iter().any(|t| !(t.is_finite() && *t > 0.0)) {
            return Some("a time that is not finite and positive".into());
        }
        if !(self.pass_low_us <= self.pass_us && self.pass_us <= self.pass_high_us) {
            return Some("an interval that does not hold its time".into());
        }
        let beyond = self.pass_us - self.work_us;
        if (self.beyond_work_us - beyond).abs() > 1e-6 * self.pass_us.max(1.0) {
            return Some("beyond_work_us is not pass_us - work_us".into());
        }
        None
    }
}

/// The cells `strategies` × `cores` of a pass-cost table: a strategy that runs every pass on
/// the calling thread (`seq`) is measured at one core only.
pub fn cells(strategies: &[StrategyName], cores: &[usize]) -> Vec<(StrategyName, usize)> {
    strategies
        .iter()
        .flat_map(|&s| {
            let mut at: Vec<usize> = cores.iter().map(|&c| s.info().effective_cores(c)).collect();
            at.dedup();
            at.into_iter().map(move |c| (s, c))
        })
        .collect()
}

/// Measures each of `cells` (strategy, cores) for `rounds` rounds of `passes` passes with
/// `work` a thread, the cells taking turns round by round so that a slow spell of the machine
/// hits them all, and returns their rows (`hardware` threads flag the oversubscribed).
/// `rounds` must be at least [`crate::results::intervals::MIN_ROUNDS`] for an interval.
/// `stop` is asked before each measurement; when it says stop, returns `None`.
pub fn table(
    cells: &[(StrategyName, usize)],
    work: Duration,
    passes: u64,
    rounds: usize,
    hardware: usize,
    stop: impl Fn() -> bool,
) -> anyhow::Result<Option<Vec<CostRow>>> {
    let mut times = vec![Vec::with_capacity(rounds); cells.len()];
    for _ in 0..rounds {
        for (&(strategy, cores), times) in cells.iter().zip(&mut times) {
            if stop() {
                return Ok(None);
            }
            let round = measure(strategy, cores, work, passes, 1)
                .with_context(|| format!("{strategy} at {cores} cores"))?;
            times.extend(round);
        }
    }
    let us = |s: f64| s * 1e6;
    let rows = cells.iter().zip(&times).map(|(&(strategy, cores), times)| {
        // Every round's time is positive and finite (a pass takes time).
        let typical = ratio(times).expect("positive times");
        let (low, high) = typical
            .interval
            .map_or((f64::NAN, f64::NAN), |i| (i.low, i.high));
        CostRow {
            strategy: strategy.info().name.to_string(),
            cores,
            work_us: us(work.as_secs_f64()),
            pass_us: us(typical.value),
            pass_low_us: us(low),
            pass_high_us: us(high),
            beyond_work_us: us(typical.value) - us(work.as_secs_f64()),
            oversubscribed: cores > hardware,
        }
    });
    Ok(Some(rows.collect()))
}

struct Rounds {
    cores: usize,
    work: Duration,
    passes: u64,
    rounds: usize,
}

impl Session for Rounds {
    type Output = Result<Vec<f64>, KernelPanic>;

    fn run<E: Executor>(self, exec: &E) -> Self::Output {
        sph_strategies::wake(exec, self.cores)?;
        let (mut out, busy) = pass_of(self.cores, self.work);
        let passes = self.passes.max(1);
        (0..self.rounds)
            .map(|_| {
                let took = busy_passes(exec, &mut out, passes, busy)?;
                Ok(took.as_secs_f64() / passes as f64)
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_pass_takes_at_least_its_work_on_every_strategy_and_each_round_is_reported() {
        let work = Duration::from_micros(20);
        for &strategy in StrategyName::ALL {
            let rounds = measure(strategy, 2, work, 20, 3).unwrap();
            assert_eq!(rounds.len(), 3, "{strategy}");
            // Every thread's share is `work`: no pass can end sooner.
            assert!(
                rounds.iter().all(|&t| t >= work.as_secs_f64()),
                "{strategy}: {rounds:?}"
            );
        }
    }

    #[test]
    fn a_table_has_one_row_per_cell_with_its_interval_around_its_typical_pass() {
        let cells = cells(&[StrategyName::Seq, StrategyName::RayonChunks], &[1, 2]);
        // seq is measured once: at more cores it still runs on the calling thread.
        assert_eq!(
            cells,
            [
                (StrategyName::Seq, 1),
                (StrategyName::RayonChunks, 1),
                (StrategyName::RayonChunks, 2)
            ]
        );
        let work = Duration::from_micros(10);
        let rows = table(&cells, work, 10, 3, 1, || false).unwrap().unwrap();
        assert_eq!(rows.len(), 3);
        for r in &rows {
            assert!(
                r.pass_low_us <= r.pass_us && r.pass_us <= r.pass_high_us,
                "{r:?}"
            );
            assert!(r.pass_us >= 10.0, "a pass takes at least its work: {r:?}");
            assert!(
                (r.beyond_work_us - (r.pass_us - 10.0)).abs() < 1e-9,
                "{r:?}"
            );
            assert_eq!(r.oversubscribed, r.cores > 1, "{r:?}");
        }
        let stopped = table(&cells, work, 10, 3, 1, || true).unwrap();
        assert!(
            stopped.is_none(),
            "a stop asked before a measurement ends the table"
        );
    }

    #[test]
    fn one_thread_alone_does_the_work_of_one_thread() {
        // seq runs every chunk on the calling thread: with two chunks' worth of work at
        // cores 2 it takes twice the work, which is what a strategy leaving a thread idle shows.
        let work = Duration::from_micros(50);
        let seq = measure(StrategyName::Seq, 2, work, 10, 2).unwrap();
        assert!(
            seq.iter().all(|&t| t >= 2.0 * work.as_secs_f64()),
            "{seq:?}"
        );
    }
}
