//! Helpers for the strategies' unit tests.

use std::collections::HashSet;
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::mpsc::RecvTimeoutError;
use std::thread::ThreadId;
use std::time::Duration;

use crate::{BuildError, Config, Executor, Session, Strategy};

/// Runs `passes` passes over `len` elements with `S` built for `cores` and `chunks`, with a
/// kernel that sleeps 1 ms per call, and returns the thread of every kernel call, per pass.
pub(crate) fn thread_ids_per_pass<S: Strategy>(
    cores: usize,
    chunks: usize,
    len: usize,
    passes: usize,
) -> Vec<Vec<ThreadId>> {
    let strategy = S::build(&Config::new(cores, chunks)).expect("the strategy builds");
    strategy
        .run(ThreadIds { len, passes })
        .expect("the threads start")
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

/// Runs `f` on its own thread and returns its result, or panics if it takes longer than a
/// minute: a hang fails the test instead of blocking it.
pub(crate) fn within_a_minute<T: Send + 'static>(f: impl FnOnce() -> T + Send + 'static) -> T {
    let (tx, rx) = std::sync::mpsc::channel();
    let thread = std::thread::spawn(move || {
        // The receiver is gone only if the watchdog already gave up.
        let _ = tx.send(f());
    });
    match rx.recv_timeout(Duration::from_secs(60)) {
        Ok(value) => value,
        Err(RecvTimeoutError::Disconnected) => match thread.join() {
            Err(payload) => std::panic::resume_unwind(payload),
            Ok(()) => unreachable!("the thread ended without sending its result"),
        },
        Err(RecvTimeoutError::Timeout) => panic!("did not finish within a minute: a hang?"),
    }
}

/// What [`run_counting`] saw.
#[derive(Debug)]
pub(crate) struct Counted {
    /// What the strategy's `run` returned: the passes that succeeded before the first error.
    pub(crate) run: Result<usize, BuildError>,
    /// Kernel calls that started, and that returned.
    pub(crate) started: usize,
    pub(crate) ended: usize,
}

/// Runs up to `passes` passes over `len` elements on `strategy` (stopping at the first failed
/// pass) under [`within_a_minute`], counting the kernel calls that start and end.
pub(crate) fn run_counting<S: Strategy + Send + 'static>(
    strategy: S,
    len: usize,
    passes: usize,
) -> Counted {
    within_a_minute(move || {
        let started = AtomicUsize::new(0);
        let ended = AtomicUsize::new(0);
        let run = strategy.run(CountingPasses {
            len,
            passes,
            started: &started,
            ended: &ended,
        });
        Counted {
            run,
            started: started.into_inner(),
            ended: ended.into_inner(),
        }
    })
}

struct CountingPasses<'a> {
    len: usize,
    passes: usize,
    started: &'a AtomicUsize,
    ended: &'a AtomicUsize,
}

impl Session for CountingPasses<'_> {
    type Output = usize;

    fn run<E: Executor>(self, exec: &E) -> usize {
        let mut out = vec![0u8; self.len];
        (0..self.passes)
            .take_while(|_| {
                exec.for_each_chunk(&mut out[..], |_, chunk| {
                    self.started.fetch_add(1, Ordering::SeqCst);
                    std::thread::sleep(Duration::from_millis(1));
                    chunk.fill(1);
                    self.ended.fetch_add(1, Ordering::SeqCst);
                })
                .is_ok()
            })
            .count()
    }
}
