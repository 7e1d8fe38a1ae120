//! What the integration tests share: the configuration grid, a recording session, the checks
//! every pass must pass, and a watchdog so that a hang fails instead of blocking.

#![allow(dead_code)] // each test binary uses a different part of this module

use std::panic::resume_unwind;
use std::sync::mpsc::{RecvTimeoutError, channel};
use std::sync::{Mutex, Once};
use std::time::Duration;

use sph_strategies::{Config, Executor, KernelPanic, Session, StrategyName};

/// Output lengths the grid covers.
pub const LENS: [usize; 4] = [0, 1, 2, 500];

/// Core counts the grid covers.
pub const CORES: [usize; 4] = [1, 2, 3, 5];

/// Requested chunk counts for an output of `len` elements: 1, 7, 64, len and 2·len (at least
/// 1, since 0 chunks is a build error), without repeats.
pub fn chunk_counts(len: usize) -> Vec<usize> {
    let mut counts = vec![1, 7, 64, len.max(1), (2 * len).max(1)];
    counts.sort_unstable();
    counts.dedup();
    counts
}

/// Calls `f` for every strategy in the registry and every configuration and length of the grid.
pub fn for_each_grid_point(mut f: impl FnMut(StrategyName, Config, usize)) {
    for &name in StrategyName::ALL {
        for len in LENS {
            for cores in CORES {
                for chunks in chunk_counts(len) {
                    f(name, Config::new(cores, chunks), len);
                }
            }
        }
    }
}

/// How many kernel calls a pass over `len` elements makes, where the strategy promises an
/// exact number (its registry [`Info`](sph_strategies::Info)); `None` where it lets the
/// runtime decide (`rayon-iter`).
pub fn promised_calls(name: StrategyName, config: Config, len: usize) -> Option<usize> {
    name.info().kernel_calls(len, &config)
}

/// Which outputs a [`Recorder`] hands to the strategy.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Outputs {
    /// One `&mut [u64]`.
    Single,
    /// `(&mut [u64], &mut [u32])`, cut in lockstep.
    Tuple,
}

/// A session that runs `passes` passes over `len` elements and records every kernel call.
///
/// In pass `p` the kernel writes `1000 * p + i` into element `i` of the values, computed from
/// the `first_index` it was given. With tuple outputs it also adds one to every element of a
/// second output, a counter array that lives for the whole session.
pub struct Recorder {
    pub len: usize,
    pub passes: usize,
    pub outputs: Outputs,
    /// `(pass, element)`: the kernel panics with [`panic_message`] when it reaches it.
    pub panic_at: Option<(usize, usize)>,
    /// The kernel panics on every element of this pass.
    pub panic_everywhere_in: Option<usize>,
}

impl Recorder {
    pub fn new(len: usize, passes: usize, outputs: Outputs) -> Self {
        Recorder {
            len,
            passes,
            outputs,
            panic_at: None,
            panic_everywhere_in: None,
        }
    }
}

/// The message of the deliberate panic at `element`.
pub fn panic_message(element: usize) -> String {
    format!("deliberate panic at element {element}")
}

/// What one pass did.
#[derive(Debug)]
pub struct Pass {
    pub result: Result<(), KernelPanic>,
    /// `(first_index, chunk length)` of every kernel call, in the order they started.
    pub calls: Vec<(usize, usize)>,
    /// The values after the pass (`u64::MAX` where nothing was written).
    pub values: Vec<u64>,
    /// How often each element has been counted so far in the session (tuple outputs only).
    pub counts: Option<Vec<u32>>,
}

impl Session for Recorder {
    type Output = Vec<Pass>;

    fn run<E: Executor>(self, exec: &E) -> Vec<Pass> {
        let mut counts = vec![0u32; self.len];
        let mut passes = Vec::with_capacity(self.passes);
        for pass in 0..self.passes {
            let mut values = vec![u64::MAX; self.len];
            let calls = Mutex::new(Vec::new());
            let panic_at = self.panic_at.filter(|&(p, _)| p == pass).map(|(_, e)| e);
            let panic_everywhere = self.panic_everywhere_in == Some(pass);
            let fill = |first: usize, values: &mut [u64]| {
                calls.lock().unwrap().push((first, values.len()));
                for (k, v) in values.iter_mut().enumerate() {
                    let i = first + k;
                    if panic_everywhere || panic_at == Some(i) {
                        panic!("{}", panic_message(i));
                    }
                    *v = 1000 * pass as u64 + i as u64;
                }
            };
            let result = match self.outputs {
                Outputs::Single => exec.for_each_chunk(&mut values[..], fill),
                Outputs::Tuple => exec.for_each_chunk(
                    (&mut values[..], &mut counts[..]),
                    |first, (v, c): (&mut [u64], &mut [u32])| {
                        assert_eq!(v.len(), c.len(), "outputs cut in lockstep");
                        fill(first, v);
                        for c in c {
                            *c += 1;
                        }
                    },
                ),
            };
            passes.push(Pass {
                result,
                calls: calls.into_inner().unwrap(),
                values,
                counts: (self.outputs == Outputs::Tuple).then(|| counts.clone()),
            });
        }
        passes
    }
}

/// Checks that pass number `pass` of a session succeeded, wrote every element exactly once
/// with the right index, and was cut into disjoint contiguous chunks covering `0..len`, in
/// the number of kernel calls the strategy promises. `completed` is how many passes before
/// this one wrote every element (for the session-long counters).
pub fn check_pass(
    what: &str,
    p: &Pass,
    pass: usize,
    completed: u32,
    len: usize,
    promised: Option<usize>,
) {
    assert_eq!(p.result, Ok(()), "{what}: pass {pass} failed");

    let mut calls = p.calls.clone();
    calls.sort_unstable();
    let mut next = 0;
    for &(first, size) in &calls {
        assert_eq!(
            first, next,
            "{what}: chunks overlap or leave a gap: {calls:?}"
        );
        assert!(
            size > 0,
            "{what}: an empty chunk was passed to the kernel: {calls:?}"
        );
        next = first + size;
    }
    assert_eq!(next, len, "{what}: chunks do not cover 0..{len}: {calls:?}");

    match promised {
        Some(n) => {
            assert_eq!(calls.len(), n, "{what}: kernel calls {calls:?}");
            let sizes = calls.iter().map(|&(_, s)| s);
            if let (Some(min), Some(max)) = (sizes.clone().min(), sizes.max()) {
                assert!(max - min <= 1, "{what}: chunks are not balanced: {calls:?}");
            }
        }
        None => assert!(calls.len() <= len, "{what}: kernel calls {calls:?}"),
    }

    for (i, &v) in p.values.iter().enumerate() {
        assert_eq!(
            v,
            1000 * pass as u64 + i as u64,
            "{what}: element {i} of pass {pass}"
        );
    }
    if let Some(counts) = &p.counts {
        for (i, &c) in counts.iter().enumerate() {
            assert_eq!(c, completed + 1, "{what}: element {i} counted {c} times");
        }
    }
}

/// Runs `f` on another thread and returns its result, failing the test if it takes longer
/// than `limit` (a hang) and re-raising its panic if it panicked.
pub fn within<T: Send + 'static>(limit: Duration, f: impl FnOnce() -> T + Send + 'static) -> T {
    let (tx, rx) = channel();
    let worker = std::thread::spawn(move || {
        let value = f();
        // The receiver is gone only if the watchdog already gave up.
        let _ = tx.send(value);
    });
    match rx.recv_timeout(limit) {
        Ok(value) => value,
        Err(RecvTimeoutError::Disconnected) => match worker.join() {
            Err(payload) => resume_unwind(payload),
            Ok(()) => unreachable!("the test thread ended without sending its result"),
        },
        Err(RecvTimeoutError::Timeout) => panic!("did not finish within {limit:?}: a hang?"),
    }
}

/// Generous enough for the whole grid on a loaded 2-core machine.
pub const LIMIT: Duration = Duration::from_secs(120);

/// Keeps the deliberate panics of these tests out of the output; other panics still print.
pub fn silence_deliberate_panics() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        let default = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            let payload = info.payload();
            let message = payload
                .downcast_ref::<String>()
                .map(String::as_str)
                .or_else(|| payload.downcast_ref::<&str>().copied());
            if !message.is_some_and(|m| m.starts_with("deliberate")) {
                default(info);
            }
        }));
    });
}
