//! A [`Placement`]'s hook runs on every worker thread a strategy starts, on that thread, with
//! its index, before the worker computes anything; and the output is the same as without it.

use std::collections::{BTreeSet, HashMap, HashSet};
use std::sync::Mutex;
use std::thread::ThreadId;

use sph_strategies::{Config, Executor, Placement, Session, StrategyName, run};

/// Every (run, worker index, thread) a hook was called with. A rayon thread may start (and
/// call its hook) after its run has returned, so every run has its own hook and id.
static SEEN: Mutex<Vec<(usize, usize, ThreadId)>> = Mutex::new(Vec::new());

/// A hook that records its calls as run `run`'s.
fn recorder(run: usize) -> Placement {
    let hook = move |index| {
        SEEN.lock()
            .unwrap()
            .push((run, index, std::thread::current().id()));
    };
    Placement::new(Box::leak(Box::new(hook)), 2)
}

/// Run `run`'s calls.
fn calls_of(run: usize) -> Vec<(usize, ThreadId)> {
    let seen = SEEN.lock().unwrap();
    seen.iter()
        .filter(|c| c.0 == run)
        .map(|c| (c.1, c.2))
        .collect()
}

/// Two passes over 64 elements; records which thread computed each element.
struct TwoPasses;

impl Session for TwoPasses {
    type Output = (Vec<u64>, Vec<ThreadId>);

    fn run<E: Executor>(self, exec: &E) -> Self::Output {
        let mut values = vec![0u64; 64];
        let mut threads = Vec::new();
        for pass in 0..2u64 {
            let by: Mutex<Vec<ThreadId>> = Mutex::new(Vec::new());
            exec.for_each_chunk(values.as_mut_slice(), |first, chunk: &mut [u64]| {
                by.lock().unwrap().push(std::thread::current().id());
                for (k, v) in chunk.iter_mut().enumerate() {
                    *v += (first + k) as u64 * (pass + 1);
                }
            })
            .expect("no kernel panics");
            threads.extend(by.into_inner().unwrap());
        }
        (values, threads)
    }
}

#[test]
fn every_worker_thread_calls_the_hook_on_itself_with_a_distinct_index_and_results_are_unchanged() {
    let mut id = 0;
    for &name in StrategyName::ALL {
        for cores in [1, 3] {
            id += 1;
            let plain = run(name, &Config::new(cores, 8), TwoPasses).expect("runs");
            let placed =
                run(name, &Config::new(cores, 8).placed(recorder(id)), TwoPasses).expect("runs");
            assert_eq!(placed.0, plain.0, "{name}: the same output");
            let seen = calls_of(id);
            let workers: HashSet<ThreadId> = placed.1.iter().copied().collect();
            let hooked: HashMap<ThreadId, BTreeSet<usize>> =
                seen.iter().fold(HashMap::new(), |mut m, &(i, t)| {
                    m.entry(t).or_default().insert(i);
                    m
                });
            let main = std::thread::current().id();
            if name == StrategyName::Seq {
                assert!(seen.is_empty(), "seq starts no thread");
                continue;
            }
            // Every thread that computed a chunk (other than the caller) was hooked first.
            for t in workers.iter().filter(|&&t| t != main) {
                assert!(
                    hooked.contains_key(t),
                    "{name}, {cores} cores: {t:?} unhooked"
                );
            }
            let indices: BTreeSet<usize> = seen.iter().map(|&(i, _)| i).collect();
            assert!(indices.iter().all(|&i| i < cores), "{name}: {indices:?}");
            if name != StrategyName::StdStatic {
                // Long-lived threads: one call each, never two with one index. (A rayon thread
                // that got no work may start after the run: fewer calls than cores is fine.)
                assert_eq!(seen.len(), indices.len(), "{name}, {cores} cores: {seen:?}");
                assert!(hooked.values().all(|i| i.len() == 1), "{name}: {hooked:?}");
            }
        }
    }
}
