//! A panic — in a kernel or in the session itself — never hangs a strategy, and a kernel
//! panic is an ordinary error after which the session can go on.

mod common;

use std::panic::{AssertUnwindSafe, catch_unwind};

use common::{
    CORES, LIMIT, Outputs, Recorder, check_pass, chunk_counts, panic_message, promised_calls,
    silence_deliberate_panics, within,
};
use sph_strategies::{Config, Executor, KernelPanic, Session, StrategyName, run};

#[test]
fn a_kernel_panic_on_one_element_is_returned_with_its_message_and_the_next_pass_still_works() {
    silence_deliberate_panics();
    within(LIMIT, || {
        for &name in StrategyName::ALL {
            for len in [1, 2, 500] {
                for cores in CORES {
                    for chunks in chunk_counts(len) {
                        let config = Config::new(cores, chunks);
                        let what = format!("{name} {config:?} len={len}");
                        let bad = len / 2;
                        let session = Recorder {
                            panic_at: Some((1, bad)),
                            ..Recorder::new(len, 3, Outputs::Tuple)
                        };
                        let passes = run(name, &config, session).unwrap();
                        let promised = promised_calls(name, config, len);
                        check_pass(&what, &passes[0], 0, 0, len, promised);
                        assert_eq!(
                            passes[1].result,
                            Err(KernelPanic {
                                message: panic_message(bad)
                            }),
                            "{what}"
                        );
                        // Pass 1 may have counted some elements; pass 2 must count each once.
                        let mut after = passes[2].counts.clone().unwrap();
                        let during = passes[1].counts.as_ref().unwrap();
                        for (a, d) in after.iter_mut().zip(during) {
                            *a -= d;
                        }
                        assert!(after.iter().all(|&c| c == 1), "{what}: pass 2 counts");
                        let values = &passes[2].values;
                        assert!(
                            values
                                .iter()
                                .enumerate()
                                .all(|(i, &v)| v == 2000 + i as u64),
                            "{what}: pass 2 values"
                        );
                    }
                }
            }
        }
    });
}

#[test]
fn a_kernel_that_panics_on_every_element_is_an_error_not_a_hang() {
    silence_deliberate_panics();
    within(LIMIT, || {
        for &name in StrategyName::ALL {
            for (cores, chunks) in [(1, 1), (2, 7), (5, 64), (3, 1000)] {
                let config = Config::new(cores, chunks);
                let session = Recorder {
                    panic_everywhere_in: Some(0),
                    ..Recorder::new(200, 2, Outputs::Single)
                };
                let passes = run(name, &config, session).unwrap();
                let err = passes[0].result.clone().unwrap_err();
                assert!(
                    err.message.starts_with("deliberate panic at element"),
                    "{name}: {err}"
                );
                let promised = promised_calls(name, config, 200);
                check_pass(
                    &format!("{name} {config:?}"),
                    &passes[1],
                    1,
                    0,
                    200,
                    promised,
                );
            }
        }
    });
}

/// Runs one pass, then panics.
struct PanickingSession;

impl Session for PanickingSession {
    type Output = ();

    fn run<E: Executor>(self, exec: &E) {
        let mut out = [0u8; 100];
        exec.for_each_chunk(&mut out[..], |_, c| c.fill(1)).unwrap();
        panic!("deliberate panic in the session");
    }
}

#[test]
fn a_session_that_panics_unwinds_out_of_run_without_hanging() {
    silence_deliberate_panics();
    within(LIMIT, || {
        for &name in StrategyName::ALL {
            for cores in CORES {
                let config = Config::new(cores, 7);
                let outcome =
                    catch_unwind(AssertUnwindSafe(|| run(name, &config, PanickingSession)));
                let payload = outcome.expect_err("the session's panic reaches the caller");
                let message = KernelPanic::from_payload(payload).message;
                assert_eq!(message, "deliberate panic in the session", "{name}");
            }
        }
    });
}
