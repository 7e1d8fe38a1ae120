//! The harness's runs with hooks, on every strategy: a traced run (the trace's executor around
//! every pass) and a run with a kernel panic injected. Here rather than in the harness's unit
//! tests because each hook is a copy of the solver for every strategy's executor: the harness
//! compiles those copies once, and these tests call them, where a unit test would compile
//! them again in the harness's test build.

use bench_sph::checksum::checksum_hex;
use bench_sph::run::fault::run_timed_steps_panicking_at;
use bench_sph::run::{RunError, Steps, run_timed, test_simulation};
use bench_sph::solver::{Simulation, StepError};
use bench_sph::trace::run_traced;
use sph_strategies::{Config, StrategyName};

fn sim(n: usize) -> Simulation {
    test_simulation(n, 7)
}

#[test]
fn a_traced_run_ends_in_the_same_state_as_an_untraced_one_on_every_strategy() {
    let config = Config::new(2, 5);
    for &strategy in StrategyName::ALL {
        let mut plain = sim(90);
        run_timed(&mut plain, strategy, &config, 3).unwrap();
        let mut traced = sim(90);
        let run = run_traced(&mut traced, strategy, &config, 3, 2).unwrap();
        assert_eq!(checksum_hex(&traced.state), checksum_hex(&plain.state));
        assert_eq!(traced.steps_done, 3, "the warm-up ran on a copy");
        let steps: Vec<usize> = run.trace.kernels.iter().map(|e| e.step).collect();
        assert_eq!(
            steps.iter().min(),
            Some(&1),
            "{strategy}: warm-up not recorded"
        );
        assert_eq!(steps.iter().max(), Some(&3), "{strategy}");
        assert_eq!(run.trace.serial.len(), 2 * 3, "{strategy}");
        assert!(
            run.trace.workers <= strategy.info().effective_cores(2),
            "{strategy}"
        );
        let last = run.trace.kernels.iter().map(|e| e.end_ns).max().unwrap();
        assert!(last <= run.trace.wall_ns, "{strategy}");
    }
}

#[test]
fn divergence_stops_a_traced_run_with_the_step_and_particle() {
    let mut s = sim(20);
    s.state.vx[3] = f64::NAN;
    let config = Config::new(2, 3);
    let err = run_traced(&mut s, StrategyName::RayonChunks, &config, 5, 0).unwrap_err();
    assert!(
        matches!(err, RunError::Step(StepError::Diverged { step: 1, .. })),
        "{err}"
    );
}

#[test]
fn an_injected_fault_fails_the_first_step_naming_the_particle_on_every_strategy() {
    for &strategy in StrategyName::ALL {
        let mut s = sim(40);
        let config = Config::new(2, 5);
        let err = run_timed_steps_panicking_at(&mut s, strategy, &config, Steps::timed(3), 17)
            .unwrap_err();
        let RunError::Step(StepError::Kernel { step: 1, source }) = err else {
            panic!("{strategy}: {err}");
        };
        assert!(
            source.message.contains("injected fault at particle 17"),
            "{strategy}: {source}"
        );
    }
}
