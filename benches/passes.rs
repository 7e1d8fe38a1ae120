//! Criterion benches: each pass (density, forces) and a full step, for every strategy in the
//! registry, at 1 core and at all hardware threads, on the paper's all-pairs N = 1000 and on
//! the grid at N = 100 000. Chunked strategies use 10 chunks per core. Run with `cargo bench`
//! or `cargo criterion` (install it with `cargo install cargo-criterion`).

use std::time::Duration;

use bench_sph::scene::dam_break;
use bench_sph::solver::{Pass, Simulation};
use bench_sph::sph::neighbors::NeighborMode;
use bench_sph::sph::params::Preset;
use criterion::measurement::WallTime;
use criterion::{BenchmarkGroup, BenchmarkId, Criterion, criterion_group, criterion_main};
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

/// Runs one benchmark inside a strategy's session, so the pool exists only once.
struct Bench<'g, 'c> {
    group: &'g mut BenchmarkGroup<'c, WallTime>,
    id: BenchmarkId,
    sim: Simulation,
    work: Work,
}

impl Session for Bench<'_, '_> {
    type Output = ();

    fn run<E: Executor>(mut self, exec: &E) {
        // Bring the neighbour lists and densities up to date before timing a single pass.
        self.sim.rebuild_neighbors();
        for pass in [Pass::Density, Pass::Forces] {
            self.sim.run_pass(exec, pass).expect("pass runs");
        }
        let sim = &mut self.sim;
        self.group.bench_function(self.id, |b| match self.work {
            Work::Pass(pass) => b.iter(|| sim.run_pass(exec, pass).expect("pass runs")),
            Work::Step => b.iter(|| sim.advance(exec, 1).expect("step runs")),
        });
    }
}

fn bench_scene(c: &mut Criterion, label: &str, mode: NeighborMode, n: usize) {
    let all = std::thread::available_parallelism().map_or(1, |n| n.get());
    let mut cores_list = vec![1, all];
    cores_list.dedup();
    for work in Work::ALL {
        let mut group = c.benchmark_group(format!("{label}/{}", work.name()));
        group
            .sample_size(20)
            .warm_up_time(Duration::from_millis(500))
            .measurement_time(Duration::from_secs(2));
        for &strategy in StrategyName::ALL {
            for &cores in &cores_list {
                if strategy == StrategyName::Seq && cores > 1 {
                    continue;
                }
                let sim = Simulation::new(
                    Preset::Seed.params(),
                    dam_break::domain(Preset::Seed, n),
                    dam_break::initial_state(Preset::Seed, n, 2019),
                    mode,
                );
                let id = BenchmarkId::new(strategy.as_str(), format!("{cores}-cores"));
                let bench = Bench {
                    group: &mut group,
                    id,
                    sim,
                    work,
                };
                sph_strategies::run(
                    strategy,
                    &Config {
                        cores,
                        chunks: 10 * cores,
                    },
                    bench,
                )
                .expect("strategy builds");
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

criterion_group!(benches, all_pairs_1000, grid_100k);
criterion_main!(benches);
