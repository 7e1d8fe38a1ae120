//! Criterion bench: what each strategy costs per pass, apart from the work. Every strategy in
//! the registry, at each core count from 1 to the machine's hardware threads, runs the passes
//! of `bench_sph::run::pass_cost` (one chunk a thread, each thread's chunk busy for the pass's
//! work a thread) in two kinds:
//! - `empty-pass`: no work. The cheapest a pass can be, but not what a pass costs in a run:
//!   with nothing to do, the thread that forks may finish every chunk before another thread
//!   takes one (rayon's work-first stealing does exactly that), so no work crosses threads.
//! - `busy-5us`: 5 µs of work a thread, so every thread must take its share for the pass to
//!   end in 5 µs: what it takes beyond is the strategy's cost of forking, handing out and
//!   joining real work at that core count.
//!
//! The strategy's threads start before the timing, as in a run. Run with `cargo bench --bench
//! overhead`; `bench-sph overhead` measures the same passes with intervals over rounds that
//! take turns across strategies.

use std::time::Duration;

use bench_sph::run::pass_cost::{busy_passes, pass_of};
use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use sph_strategies::{Executor, Session, StrategyName};

/// `iters` passes over `out`, each element busy for `busy`, timed inside the strategy's
/// session.
struct Passes<'o> {
    out: &'o mut [u64],
    iters: u64,
    busy: Duration,
}

impl Session for Passes<'_> {
    type Output = Duration;

    fn run<E: Executor>(self, exec: &E) -> Duration {
        busy_passes(exec, self.out, self.iters, self.busy).expect("a pass of the benchmark runs")
    }
}

fn passes(c: &mut Criterion) {
    let all = std::thread::available_parallelism().map_or(1, |n| n.get());
    for (kind, work) in [
        ("empty-pass", Duration::ZERO),
        ("busy-5us", Duration::from_micros(5)),
    ] {
        let mut group = c.benchmark_group(format!("overhead/{kind}"));
        group
            .sample_size(30)
            .warm_up_time(Duration::from_millis(300))
            .measurement_time(Duration::from_secs(1));
        for &strategy in StrategyName::ALL {
            for cores in 1..=all {
                // `seq` runs every pass on the calling thread: one core only.
                if strategy.info().effective_cores(cores) < cores {
                    continue;
                }
                let config = sph_strategies::Config::new(cores, cores);
                let (mut out, busy) = pass_of(cores, work);
                let id = BenchmarkId::new(strategy.as_str(), format!("{cores}-cores"));
                group.bench_function(id, |b| {
                    b.iter_custom(|iters| {
                        let passes = Passes {
                            out: &mut out,
                            iters,
                            busy,
                        };
                        sph_strategies::run(strategy, &config, passes).expect("strategy builds")
                    })
                });
            }
        }
        group.finish();
    }
}

criterion_group!(benches, passes);
criterion_main!(benches);
