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

use sph_strategies::{Config, Executor, KernelPanic, Session, StrategyName};

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
