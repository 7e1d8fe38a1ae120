//! Criterion benches: each pass (density; forces, which also move the particles) and a full
//! step, for every strategy in the registry, at 1 core and at all hardware threads, on the
//! paper's all-pairs N = 1000 and on the grid at N = 100 000, each from the seed dam break
//! after 100 steps. Chunked strategies use 10 chunks per core. The `simd/...` groups run
//! `seq` on each SIMD path this CPU has (`--simd`): the density pass, where the neighbour
//! tests run, and a whole step, on both scenes and on the grid at N = 1000 in cell order. Run
//! with `cargo bench` or `cargo criterion` (install it with `cargo install cargo-criterion`).

use std::time::{Duration, Instant};

use bench_sph::models::Preset;
use bench_sph::models::mueller::scene;
use bench_sph::simd::SimdPath;
use bench_sph::solver::{Pass, Simulation};
use bench_sph::sph::neighbors::{NeighborMode, SumOrder};
use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use sph_strategies::seq::SeqExecutor;
use sph_strategies::{Config, Executor, Session, StrategyName};

/// What one benchmark measures.
#[derive(Clone, Copy)]
enum Work {
    Pass(Pass),
    Step,
}

impl Work {
    const ALL: [Work; 3] = [
        Work::Pass(Pass::Density),
        Work::Pass(Pass::Forces),
        Work::Step,
    ];

    fn name(self) -> &'static str {
        match self {
            Work::Pass(p) => p.as_str(),
            Work::Step => "step",
        }
    }
}

/// Steps run before benchmarking, so that every benchmark starts from the same fluid in
/// motion rather than from the dam at rest.
const SETTLE_STEPS: usize = 100;

/// Times `iters` repetitions of one benchmark's work inside a strategy's session (the
/// strategy's threads are started before the session, outside the timing). Every repetition
/// starts from a fresh copy of `start` (made outside the timing; the force pass moves the
/// particles), so every strategy measures the same work.
struct TimedIters<'s> {
    start: &'s Simulation,
    sim: &'s mut Simulation,
    work: Work,
    iters: u64,
}

impl Session for TimedIters<'_> {
    type Output = Duration;

    fn run<E: Executor>(self, exec: &E) -> Duration {
        let mut total = Duration::ZERO;
        for _ in 0..self.iters {
            self.sim.clone_from(self.start);
            let begin = Instant::now();
            match self.work {
                Work::Pass(pass) => self.sim.run_pass(exec, pass).expect("pass runs"),
                Work::Step => self.sim.advance(exec, 1).expect("step runs"),
            }
            total += begin.elapsed();
        }
        total
    }
}

/// Times `iters` repetitions of `work` from `start` on `strategy` (see [`TimedIters`]).
fn time_iters(
    start: &Simulation,
    sim: &mut Simulation,
    work: Work,
    iters: u64,
    strategy: StrategyName,
    config: &Config,
) -> Duration {
    let timed = TimedIters {
        start,
        sim,
        work,
        iters,
    };
    sph_strategies::run(strategy, config, timed).expect("strategy builds")
}

/// The seed dam break of `n` particles after [`SETTLE_STEPS`] steps, with the next step's
/// neighbour lists and densities in place (so either pass can be timed alone).
fn settled(mode: NeighborMode, n: usize) -> Simulation {
    let mut sim = Simulation::new(
        Preset::Seed.params(),
        scene::domain(Preset::Seed, n),
        scene::initial_state(Preset::Seed, n, 2019),
        mode,
    );
    sim.advance(&SeqExecutor, SETTLE_STEPS)
        .expect("settling runs");
    sim.rebuild_neighbors();
    sim.run_pass(&SeqExecutor, Pass::Density)
        .expect("the density pass runs");
    sim
}

fn bench_scene(c: &mut Criterion, label: &str, mode: NeighborMode, n: usize) {
    let all = std::thread::available_parallelism().map_or(1, |n| n.get());
    let mut cores_list = vec![1, all];
    cores_list.dedup();
    let start = settled(mode, n);
    for work in Work::ALL {
        let mut group = c.benchmark_group(format!("{label}/{}", work.name()));
        group
            .sample_size(20)
            .warm_up_time(Duration::from_millis(500))
            .measurement_time(Duration::from_secs(2));
        for &strategy in StrategyName::ALL {
            for &cores in &cores_list {
                if strategy.info().effective_cores(cores) < cores {
                    continue;
                }
                let mut sim = start.clone();
                let config = Config::new(cores, 10 * cores);
                let id = BenchmarkId::new(strategy.as_str(), format!("{cores}-cores"));
                group.bench_function(id, |b| {
                    b.iter_custom(|iters| {
                        time_iters(&start, &mut sim, work, iters, strategy, &config)
                    })
                });
            }
        }
        group.finish();
    }
}

fn all_pairs_1000(c: &mut Criterion) {
    bench_scene(c, "all-pairs-n1000", NeighborMode::AllPairs, 1000);
}

fn grid_100k(c: &mut Criterion) {
    bench_scene(c, "grid-n100000", NeighborMode::Grid, 100_000);
}

/// Each SIMD path this CPU runs, sequentially, on both scenes and on the grid at N = 1000 in
/// cell order (whose density sums in eight lanes): the density pass (the neighbour tests)
/// and a whole step.
fn simd_paths(c: &mut Criterion) {
    let scenes = [
        (
            "all-pairs-n1000",
            NeighborMode::AllPairs,
            1000,
            SumOrder::Index,
        ),
        ("grid-n100000", NeighborMode::Grid, 100_000, SumOrder::Index),
        (
            "grid-n1000-cell-order",
            NeighborMode::Grid,
            1000,
            SumOrder::Cell,
        ),
    ];
    let seq = Config::new(1, 1);
    for (label, mode, n, order) in scenes {
        let settled = settled(mode, n)
            .with_sum_order(order)
            .expect("the grid has cell order");
        for work in [Work::Pass(Pass::Density), Work::Step] {
            let mut group = c.benchmark_group(format!("simd/{label}/{}", work.name()));
            group
                .sample_size(20)
                .warm_up_time(Duration::from_millis(500))
                .measurement_time(Duration::from_secs(2));
            for path in SimdPath::available() {
                let start = settled.clone().with_simd(path).expect("available");
                let mut sim = start.clone();
                group.bench_function(path.as_str(), |b| {
                    b.iter_custom(|iters| {
                        time_iters(&start, &mut sim, work, iters, StrategyName::Seq, &seq)
                    })
                });
            }
            group.finish();
        }
    }
}

criterion_group!(benches, all_pairs_1000, grid_100k, simd_paths);
criterion_main!(benches);
