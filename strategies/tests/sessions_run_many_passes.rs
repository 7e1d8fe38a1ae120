//! A session may call `for_each_chunk` as often as it likes on the same executor.

mod common;

use common::{LIMIT, Outputs, Recorder, check_pass, promised_calls, within};
use sph_strategies::{Config, StrategyName, run};

#[test]
fn a_session_can_run_25_passes_on_one_executor() {
    within(LIMIT, || {
        for &name in StrategyName::ALL {
            for config in [
                Config::new(1, 1),
                Config::new(2, 7),
                Config::new(3, 64),
                Config::new(5, 1000),
            ] {
                for len in [0, 1, 500] {
                    let what = format!("{name} {config:?} len={len}");
                    let passes = run(name, &config, Recorder::new(len, 25, Outputs::Tuple))
                        .unwrap_or_else(|e| panic!("{what}: {e}"));
                    assert_eq!(passes.len(), 25, "{what}");
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
fn the_registry_lists_seq_first_and_every_name_once() {
    let names = StrategyName::names();
    assert_eq!(names.first(), Some(&"seq"));
    let mut unique = names.clone();
    unique.sort_unstable();
    unique.dedup();
    assert_eq!(unique.len(), names.len(), "{names:?}");
    for &name in StrategyName::ALL {
        let info = name.info();
        assert!(
            !info.description.is_empty() && !info.description.contains('\n'),
            "{name}"
        );
    }
}
