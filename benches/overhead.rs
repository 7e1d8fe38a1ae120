//! Criterion bench: what each strategy costs per pass, apart from the work. Every strategy in
//! the registry, at each core count from 1 to the machine's hardware threads, runs passes over
//! a tiny output (16 `u64`s a core) cut into one chunk per core (`--chunks` = cores, the
//! least a chunked strategy can be given), in two kinds:
//! - `empty-pass`: the kernel only writes each element's index. This is the cheapest a pass
//!   can be, but not what a pass costs in a run: with nothing to do, the thread that forks
//!   may finish every chunk before another thread takes one (rayon's work-first stealing
//!   does exactly that), so no work crosses threads.
//! - `busy-5us`: each element also keeps its thread busy for 5 µs / 16 (a clock loop), so a
//!   pass is 5 µs of work per core however a strategy cuts it, and every thread must take its
//!   share for the pass to end in 5 µs. A pass's time over 5 µs is the strategy's cost of
//!   forking, handing out and joining real work at that core count (with its kernel calls:
//!   `rayon-spawn` makes one per element, each reading the clock), and a strategy that leaves
//!   a core idle shows it as up to 5 µs more.
//!
//! The strategy's threads start before the timing, as in a run. Run with `cargo bench --bench
//! overhead`; criterion prints each time per pass with its interval. A pass of the paper's
//! workload (all-pairs, N = 1000) is tens of µs of work on one core: set the two side by side
//! to see where a strategy's speedup must bend.

use std::hint::black_box;
use std::time::{Duration, Instant};

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use sph_strategies::{Config, Executor, Session, StrategyName};

/// Elements of the output per core: two cache lines each.
const PER_CORE: usize = 16;

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
        let Passes { out, iters, busy } = self;
        let begin = Instant::now();
        for _ in 0..iters {
            exec.for_each_chunk(&mut *out, |first, chunk: &mut [u64]| {
                let start = Instant::now();
                let until = busy * chunk.len() as u32;
                while start.elapsed() < until {}
                for (k, x) in chunk.iter_mut().enumerate() {
                    *x = (first + k) as u64;
                }
            })
            .expect("a pass of the benchmark runs");
        }
        let elapsed = begin.elapsed();
        black_box(out);
        elapsed
    }
}

fn passes(c: &mut Criterion) {
    let all = std::thread::available_parallelism().map_or(1, |n| n.get());
    for (kind, busy) in [
        ("empty-pass", Duration::ZERO),
        ("busy-5us", Duration::from_micros(5) / PER_CORE as u32),
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
                let config = Config::new(cores, cores);
                let mut out = vec![0u64; PER_CORE * cores];
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
