//! Helpers for the strategies' unit tests.

use std::collections::HashSet;
use std::sync::Mutex;
use std::thread::ThreadId;
use std::time::Duration;

use crate::{Config, Executor, Session, Strategy};

/// Runs `passes` passes over `len` elements with `S` built for `cores` and `chunks`, with a
/// kernel that sleeps 1 ms per call, and returns the thread of every kernel call, per pass.
pub(crate) fn thread_ids_per_pass<S: Strategy>(
    cores: usize,
    chunks: usize,
    len: usize,
    passes: usize,
) -> Vec<Vec<ThreadId>> {
    let strategy = S::build(&Config { cores, chunks }).expect("the strategy builds");
    strategy.run(ThreadIds { len, passes })
}

/// How many different threads appear in `ids`.
pub(crate) fn distinct(ids: &[ThreadId]) -> usize {
    ids.iter().collect::<HashSet<_>>().len()
}

struct ThreadIds {
    len: usize,
    passes: usize,
}

impl Session for ThreadIds {
    type Output = Vec<Vec<ThreadId>>;

    fn run<E: Executor>(self, exec: &E) -> Self::Output {
        (0..self.passes)
            .map(|_| {
                let mut out = vec![0u8; self.len];
                let ids = Mutex::new(Vec::new());
                exec.for_each_chunk(&mut out[..], |_, _| {
                    std::thread::sleep(Duration::from_millis(1));
                    ids.lock().unwrap().push(std::thread::current().id());
                })
                .expect("the kernel does not panic");
                ids.into_inner().unwrap()
            })
            .collect()
    }
}
