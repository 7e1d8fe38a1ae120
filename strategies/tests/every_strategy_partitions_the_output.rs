//! Every registered strategy, on every configuration of the grid, calls the kernel once per
//! chunk of a partition of the output.

mod common;

use common::{LIMIT, Outputs, Recorder, check_pass, for_each_grid_point, promised_calls, within};
use sph_strategies::{BuildError, Config, StrategyName, run};

fn check_grid(outputs: Outputs) {
    within(LIMIT, move || {
        for_each_grid_point(|name, config, len| {
            let what = format!("{name} {config:?} len={len} {outputs:?}");
            let passes = run(name, &config, Recorder::new(len, 3, outputs)).unwrap();
            assert_eq!(passes.len(), 3);
            for (pass, p) in passes.iter().enumerate() {
                let promised = promised_calls(name, config, len);
                check_pass(&what, p, pass, pass as u32, len, promised);
            }
        });
    });
}

#[test]
fn a_single_output_is_written_exactly_once_by_disjoint_contiguous_chunks() {
    check_grid(Outputs::Single);
}

#[test]
fn tuple_outputs_are_cut_in_lockstep_and_every_element_is_counted_once_per_pass() {
    check_grid(Outputs::Tuple);
}

#[test]
fn each_strategy_makes_exactly_the_number_of_kernel_calls_it_promises() {
    within(LIMIT, || {
        for_each_grid_point(|name, config, len| {
            let passes = run(name, &config, Recorder::new(len, 1, Outputs::Single)).unwrap();
            let calls = passes[0].calls.len();
            match promised_calls(name, config, len) {
                Some(n) => assert_eq!(calls, n, "{name} {config:?} len={len}"),
                // rayon-iter: rayon decides, between one call and one per element.
                None => assert!(
                    (len.min(1)..=len).contains(&calls),
                    "{name} {config:?} len={len}: {calls} calls"
                ),
            }
        });
    });
}

#[test]
fn more_cores_and_more_chunks_than_elements_neither_panic_nor_deadlock() {
    within(LIMIT, || {
        for &name in StrategyName::ALL {
            for len in [1, 2, 3] {
                for (cores, chunks) in [(8, 100), (len + 1, len + 1), (16, 1), (1, 1000)] {
                    let config = Config::new(cores, chunks);
                    let what = format!("{name} {config:?} len={len}");
                    let passes = run(name, &config, Recorder::new(len, 5, Outputs::Tuple))
                        .unwrap_or_else(|e| panic!("{what}: {e}"));
                    for (pass, p) in passes.iter().enumerate() {
                        let promised = promised_calls(name, config, len);
                        check_pass(&what, p, pass, pass as u32, len, promised);
                    }
                }
            }
        }
    });
}

#[test]
fn every_strategy_refuses_zero_cores_or_zero_chunks() {
    for &name in StrategyName::ALL {
        let session = || Recorder::new(1, 1, Outputs::Single);
        let zero_cores = run(name, &Config::new(0, 1), session());
        assert!(matches!(zero_cores, Err(BuildError::ZeroCores)), "{name}");
        let zero_chunks = run(name, &Config::new(1, 0), session());
        assert!(matches!(zero_chunks, Err(BuildError::ZeroChunks)), "{name}");
    }
}
