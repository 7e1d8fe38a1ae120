//! Every strategy gives the sequential run's bits, whatever the search (the grid with either
//! list key, in index or cell order), cores, chunks, SIMD path and thread placement (`--pin`) (the portable path's unpinned sequential run is the reference),
//! and a panic inside a kernel becomes an error of the run (never a hang) on every strategy.
//! Whichever thread of whichever strategy runs a kernel call, it runs the code of the SIMD path
//! that `seq` runs.

use std::collections::BTreeSet;
use std::sync::Mutex;
use std::thread::ThreadId;
use std::time::Duration;

use bench_sph::models::Preset;
use bench_sph::models::mueller;
use bench_sph::run::{self, run_timed};
use bench_sph::scene::Scene;
use bench_sph::simd::SimdPath;
use bench_sph::solver::Simulation;
use bench_sph::sph::neighbors::{GridKeys, NeighborMode, SumOrder};
use bench_sph::sph::state::{FIELD_NAMES, State};
use sph_strategies::{Config, Executor, KernelPanic, Session, Split, StrategyName};

use crate::common;

const N: usize = 500;
const STEPS: usize = 25;

/// A neighbour search, the keys of the grid's lists (all-pairs lists indices whatever this
/// says) and the order its sums run in.
type Search = (NeighborMode, GridKeys, SumOrder);

/// Every search, the grid with either key (N particles get index keys by size; position keys,
/// what large runs get, are forced) in either order.
const SEARCHES: [Search; 5] = [
    (NeighborMode::AllPairs, GridKeys::Index, SumOrder::Index),
    (NeighborMode::Grid, GridKeys::Index, SumOrder::Index),
    (NeighborMode::Grid, GridKeys::Position, SumOrder::Index),
    (NeighborMode::Grid, GridKeys::Index, SumOrder::Cell),
    (NeighborMode::Grid, GridKeys::Position, SumOrder::Cell),
];

fn simulation(preset: Preset, (mode, keys, order): Search) -> Simulation {
    let scene = Scene::dam_break(preset, N, 7).unwrap();
    let sim = scene.simulate(mode).with_grid_keys(keys);
    sim.with_sum_order(order).unwrap()
}

fn run(
    preset: Preset,
    search: Search,
    simd: SimdPath,
    strategy: StrategyName,
    cores: usize,
    chunks: usize,
) -> State {
    let mut sim = simulation(preset, search).with_simd(simd).unwrap();
    run_timed(&mut sim, strategy, &Config::new(cores, chunks), STEPS)
        .unwrap_or_else(|e| panic!("{strategy} cores={cores} chunks={chunks}: {e}"));
    sim.state
}

/// [`run`] without what `run_timed` does around the steps: `STEPS` steps of the simulation in
/// one session of `strategy` on `cores` threads and `chunks` chunks
/// (`run::run_steps_only`), the same `advance` on the same executor, so the same bits to
/// compare. What it leaves out is the wake
/// (`sph_strategies::wake`): untimed passes on a scratch buffer that spin until the threads
/// hold their cores, at least 10 ms on a quiet machine and up to 0.15 s on a busy one (as
/// beside the suite's other test thread), before every run on more than one thread: 2 250 of
/// the matrix's 3 615 runs, which took 160-370 s with it and 40-50 s without. The wake
/// computes nothing the steps read; runs through `run_timed`, wake included, are still
/// checked against the sequential bits on every strategy, preset and search (1-3 cores) by
/// the placement test below, and by the SIMD-path and band-sort tests.
fn run_steps_only(
    preset: Preset,
    search: Search,
    simd: SimdPath,
    strategy: StrategyName,
    cores: usize,
    chunks: usize,
) -> State {
    let what = format!("{strategy} cores={cores} chunks={chunks}");
    let mut sim = simulation(preset, search).with_simd(simd).unwrap();
    run::run_steps_only(&mut sim, strategy, &Config::new(cores, chunks), STEPS)
        .unwrap_or_else(|e| panic!("{what}: {:#}", anyhow::Error::new(e)));
    sim.state
}

fn first_bit_difference(a: &State, b: &State) -> Option<String> {
    FIELD_NAMES
        .iter()
        .zip(a.fields().iter().zip(b.fields()))
        .find_map(|(name, (fa, fb))| {
            fa.iter()
                .zip(fb.iter())
                .position(|(x, y)| x.to_bits() != y.to_bits())
                .map(|i| format!("{name}[{i}]: {:e} vs {:e}", fa[i], fb[i]))
        })
}

/// The portable path and the widest this machine runs (CI runs both).
fn tested_paths() -> Vec<SimdPath> {
    let mut paths = vec![SimdPath::Portable, SimdPath::widest()];
    paths.dedup();
    paths
}

#[test]
fn every_strategy_cores_and_chunks_gives_the_bits_of_the_sequential_run() {
    for preset in Preset::ALL {
        for search in SEARCHES {
            let reference = run(preset, search, SimdPath::Portable, StrategyName::Seq, 1, 1);
            for simd in tested_paths() {
                for &strategy in StrategyName::ALL {
                    for cores in [1, 2, 3, 5] {
                        for chunks in [1, 7, 64, N, 2 * N] {
                            let got = run_steps_only(preset, search, simd, strategy, cores, chunks);
                            if let Some(diff) = first_bit_difference(&got, &reference) {
                                let (mode, keys, order) = search;
                                panic!(
                                    "{preset} {mode} {keys:?} keys, order {order} {simd} \
                                     {strategy} cores={cores} chunks={chunks}: {diff}"
                                );
                            }
                        }
                    }
                }
            }
        }
    }
}

#[test]
fn a_grid_large_enough_to_sort_in_bands_gives_the_sequential_bits_on_every_strategy() {
    // From 65 536 particles on, a grid on more than one thread sorts its cells in bands on the
    // executor (`seq` sorts serially): every strategy's cut must give the serial sort's bits.
    // In cell order the sums also run in the sorted order itself. (A dam at rest has about
    // one particle a cell, so the order within a cell is checked by the unit test of
    // `grid::sort`, on crowded cells.)
    let n = 70_000;
    let scene = Scene::dam_break(Preset::Seed, n, 7).unwrap();
    for order in [SumOrder::Index, SumOrder::Cell] {
        let run = |strategy: StrategyName, cores: usize, chunks: usize| {
            let sim = scene.clone().simulate(NeighborMode::Grid);
            let mut sim = sim.with_sum_order(order).unwrap();
            run_timed(&mut sim, strategy, &Config::new(cores, chunks), 3)
                .unwrap_or_else(|e| panic!("{strategy} cores={cores} chunks={chunks}: {e}"));
            sim.state
        };
        let reference = run(StrategyName::Seq, 1, 1);
        for &strategy in StrategyName::ALL {
            for (cores, chunks) in [(2, 1), (2, 10), (3, 64), (5, 1000)] {
                let got = run(strategy, cores, chunks);
                if let Some(diff) = first_bit_difference(&got, &reference) {
                    panic!(
                        "N = {n}, grid, order {order}, {strategy} cores={cores} \
                         chunks={chunks}: {diff}"
                    );
                }
            }
        }
    }
}

#[test]
fn every_strategy_pinned_compact_or_spread_gives_the_bits_of_the_unpinned_sequential_run() {
    use bench_sph::placement::placement;
    use bench_sph::topology::Pin;
    for preset in Preset::ALL {
        for search @ (mode, keys, order) in SEARCHES {
            let reference = run(preset, search, SimdPath::Portable, StrategyName::Seq, 1, 1);
            for pin in [Pin::Compact, Pin::Spread] {
                let placed = placement(pin).expect("this machine accepts its own CPUs");
                for &strategy in StrategyName::ALL {
                    // More threads than CPUs too: worker i goes to CPU i mod the order's length.
                    for cores in [1, 2, 3] {
                        let mut sim = simulation(preset, search);
                        let config = Config::new(cores, 7).placed(placed);
                        let what = format!(
                            "{preset} {mode} {keys:?} keys, order {order} --pin {pin} {strategy} cores={cores}"
                        );
                        run_timed(&mut sim, strategy, &config, STEPS)
                            .unwrap_or_else(|e| panic!("{what}: {e}"));
                        if let Some(diff) = first_bit_difference(&sim.state, &reference) {
                            panic!("{what}: {diff}");
                        }
                    }
                }
            }
        }
    }
}

#[test]
fn every_simd_path_this_machine_runs_gives_the_portable_bits() {
    eprintln!("SIMD paths available here: {:?}", SimdPath::available());
    for preset in Preset::ALL {
        for search @ (mode, keys, order) in SEARCHES {
            let reference = run(preset, search, SimdPath::Portable, StrategyName::Seq, 1, 1);
            for simd in SimdPath::available() {
                for (strategy, cores, chunks) in [
                    (StrategyName::Seq, 1, 1),
                    (StrategyName::RayonChunks, 2, 7),
                    (StrategyName::CrossbeamPool, 3, 64),
                ] {
                    let got = run(preset, search, simd, strategy, cores, chunks);
                    if let Some(diff) = first_bit_difference(&got, &reference) {
                        panic!(
                            "{preset} {mode} {keys:?} keys, order {order} {simd} {strategy}: {diff}"
                        );
                    }
                }
            }
        }
    }
}

/// Records, from inside every kernel call, the thread that runs it and the SIMD paths its
/// kernel was compiled for: a pass picks its path once (`with_lanes!`) and hands the strategy a
/// kernel monomorphised for it, whose type names the lanes (`mueller::density<_, Avx512, _>`).
struct PathRecorder<'a, E> {
    inner: &'a E,
    calls: &'a Mutex<Vec<(ThreadId, BTreeSet<SimdPath>)>>,
}

impl<E: Executor> Executor for PathRecorder<'_, E> {
    fn for_each_chunk<O, F>(&self, out: O, kernel: F) -> Result<(), KernelPanic>
    where
        O: Split,
        F: Fn(usize, O) + Sync,
    {
        let paths = paths_named_in(std::any::type_name::<F>());
        self.inner.for_each_chunk(out, |first, chunk| {
            let call = (std::thread::current().id(), paths.clone());
            self.calls.lock().unwrap().push(call);
            kernel(first, chunk);
        })
    }

    fn threads(&self) -> usize {
        self.inner.threads()
    }
}

/// The SIMD paths whose lanes type a kernel's type name names (none for a kernel that does not
/// depend on the path, such as the grid's rebuild).
fn paths_named_in(type_name: &str) -> BTreeSet<SimdPath> {
    let lanes = [
        (SimdPath::Portable, "::Portable"),
        (SimdPath::Avx2, "::Avx2"),
        (SimdPath::Avx512, "::Avx512"),
    ];
    lanes
        .into_iter()
        .filter(|(_, name)| {
            type_name.match_indices(name).any(|(at, _)| {
                let next = type_name[at + name.len()..].chars().next();
                !next.is_some_and(|c| c.is_alphanumeric() || c == '_')
            })
        })
        .map(|(path, _)| path)
        .collect()
}

/// Runs `steps` steps of `sim` on `strategy` with every kernel call recorded: its thread and the
/// paths its kernel was compiled for.
fn record_paths(
    sim: &mut Simulation,
    strategy: StrategyName,
    config: &Config,
    steps: usize,
) -> Vec<(ThreadId, BTreeSet<SimdPath>)> {
    struct Steps<'a> {
        sim: &'a mut Simulation,
        steps: usize,
        calls: &'a Mutex<Vec<(ThreadId, BTreeSet<SimdPath>)>>,
    }
    impl Session for Steps<'_> {
        type Output = ();
        fn run<E: Executor>(self, exec: &E) {
            let calls = self.calls;
            let recorder = PathRecorder { inner: exec, calls };
            self.sim
                .advance(&recorder, self.steps)
                .expect("the steps run");
        }
    }
    let calls = Mutex::new(Vec::new());
    sph_strategies::run(
        strategy,
        config,
        Steps {
            sim,
            steps,
            calls: &calls,
        },
    )
    .expect("starts");
    calls.into_inner().unwrap()
}

#[test]
fn every_strategys_threads_run_the_simd_path_that_seq_runs() {
    // Measured once: crossbeam-pool on 1 core took 3.4x seq's time on AVX-512 and AVX2 (and
    // the same time on the portable path), as if its thread ran other instructions. It did
    // not (a stack temporary straddled a page: see `simd::Near8`); this holds that it never
    // does: whichever thread runs a kernel call, it runs the code of the path seq runs.
    let me = std::thread::current().id();
    for simd in SimdPath::available() {
        for search @ (mode, keys, order) in SEARCHES {
            let fresh = || simulation(Preset::Seed, search).with_simd(simd).unwrap();
            let lanes_of = |calls: &[(ThreadId, BTreeSet<SimdPath>)]| -> BTreeSet<SimdPath> {
                calls.iter().flat_map(|(_, p)| p.iter().copied()).collect()
            };
            let seq = record_paths(&mut fresh(), StrategyName::Seq, &Config::new(1, 1), 3);
            let seq_paths = lanes_of(&seq);
            if mode == NeighborMode::AllPairs {
                assert_eq!(
                    seq_paths,
                    BTreeSet::from([simd]),
                    "seq, all-pairs, --simd {simd}"
                );
            } else {
                assert!(
                    seq_paths.contains(&simd),
                    "seq, grid, --simd {simd}: {seq_paths:?}"
                );
            }
            for &strategy in StrategyName::ALL {
                for (cores, chunks) in [(1, 10), (2, 7)] {
                    let what = format!(
                        "{mode} {keys:?} keys, order {order}, --simd {simd}, {strategy} \
                         cores={cores} chunks={chunks}"
                    );
                    let calls =
                        record_paths(&mut fresh(), strategy, &Config::new(cores, chunks), 3);
                    assert_eq!(lanes_of(&calls), seq_paths, "{what}");
                    for (thread, paths) in &calls {
                        assert!(
                            paths.is_subset(&seq_paths),
                            "{what}: {thread:?} ran {paths:?}"
                        );
                    }
                    // The kernels ran on the strategy's own threads, not only on this one.
                    if strategy != StrategyName::Seq {
                        let elsewhere = calls.iter().any(|(t, p)| *t != me && !p.is_empty());
                        assert!(
                            elsewhere,
                            "{what}: no path-carrying call off the test's thread"
                        );
                    }
                }
            }
        }
    }
}

#[test]
fn a_path_this_cpu_lacks_is_refused() {
    for simd in SimdPath::ALL {
        let sim = Scene::dam_break(Preset::Seed, 10, 1)
            .unwrap()
            .simulate(NeighborMode::Grid);
        assert_eq!(sim.with_simd(simd).is_ok(), simd.is_available(), "{simd}");
    }
}

#[test]
fn more_cores_and_chunks_than_particles_still_match_the_sequential_run() {
    let tiny = |strategy, cores, chunks| {
        let init = mueller::scene::initial_state(Preset::Seed, 3, 1);
        let mut sim = Simulation::new(
            Preset::Seed.params(),
            mueller::scene::domain(Preset::Seed, 3),
            init,
            NeighborMode::Grid,
        );
        run_timed(&mut sim, strategy, &Config::new(cores, chunks), 10).expect("runs");
        sim.state
    };
    let reference = tiny(StrategyName::Seq, 1, 1);
    for &strategy in StrategyName::ALL {
        assert_eq!(
            first_bit_difference(&tiny(strategy, 8, 50), &reference),
            None,
            "{strategy}"
        );
    }
}

#[test]
fn a_kernel_panic_on_a_worker_is_an_error_of_the_run_for_every_strategy() {
    for &strategy in StrategyName::ALL {
        let mut cmd = common::bench_sph();
        cmd.args([
            "simulate",
            "--strategy",
            strategy.as_str(),
            "--cores",
            "2",
            "--chunks",
            "7",
        ])
        .args(["--n", "200", "--steps", "50", "--inject-panic-at", "150"]);
        // A hang is killed after a minute (a bound, not a timing) and then fails below.
        let o = assert_cmd::Command::from_std(cmd)
            .timeout(Duration::from_secs(60))
            .output()
            .expect("binary runs");
        let err = common::text(&o.stderr);
        assert!(!o.status.success(), "{strategy}: exited successfully");
        assert!(
            err.contains("Error: step 1 failed") && err.contains("injected fault at particle 150"),
            "{strategy}: {err}"
        );
        assert!(!err.contains("RUST_BACKTRACE"), "{strategy}: {err}");
    }
}
