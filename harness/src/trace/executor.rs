//! The wrapping executor that times each kernel call of a strategy.

use sph_strategies::{Executor, KernelPanic, Split};

use super::recorder::{KernelEvent, Phase, Recorder};

/// Runs passes on `inner` and records one [`KernelEvent`] per kernel call, labelled with the
/// phase (pass or grid rebuild) and step it was built for (one `TracingExecutor` per phase of
/// a step).
///
/// It changes neither the chunks nor the threads: `inner` still decides both, and the kernel
/// it calls is the pass's own kernel with a clock read on either side. Untraced runs never see
/// this type, so they pay nothing for it.
#[derive(Debug)]
pub struct TracingExecutor<'a, E> {
    inner: &'a E,
    recorder: &'a Recorder,
    phase: Phase,
    step: usize,
}

impl<'a, E: Executor> TracingExecutor<'a, E> {
    /// Wraps `inner` for `phase` of (1-based) step `step`.
    pub fn new(inner: &'a E, recorder: &'a Recorder, phase: impl Into<Phase>, step: usize) -> Self {
        TracingExecutor {
            inner,
            recorder,
            phase: phase.into(),
            step,
        }
    }
}

impl<E: Executor> Executor for TracingExecutor<'_, E> {
    fn for_each_chunk<O, F>(&self, out: O, kernel: F) -> Result<(), KernelPanic>
    where
        O: Split,
        F: Fn(usize, O) + Sync,
    {
        let (rec, phase, step) = (self.recorder, self.phase, self.step);
        rec.begin_pass();
        self.inner.for_each_chunk(out, |first, chunk| {
            timed_call(rec, phase, step, first, chunk, &kernel);
        })
    }

    fn threads(&self) -> usize {
        self.inner.threads()
    }
}

/// Runs `kernel(first, chunk)` and records it as one call of `phase` in `step`.
#[inline(always)]
fn timed_call<O: Split, F: Fn(usize, O)>(
    rec: &Recorder,
    phase: Phase,
    step: usize,
    first: usize,
    chunk: O,
    kernel: &F,
) {
    // The slot is taken before the first clock read, so that a slot's events never overlap
    // even when a fresh thread takes over a slot (see `recorder`).
    let slot = rec.worker();
    let len = chunk.len();
    let start_ns = rec.now_ns();
    kernel(first, chunk);
    let end_ns = rec.now_ns();
    slot.push(KernelEvent {
        phase,
        step,
        worker: slot.worker,
        thread: slot.thread,
        first,
        len,
        start_ns,
        end_ns,
    });
}

/// What recording adds to one kernel call, measured on the calling thread: the mean time, in
/// nanoseconds, of `calls` recorded calls of an empty kernel (slot lookup, two clock reads
/// and the push). An estimate for the cost of tracing that does not depend on a quiet
/// machine: a run pays about this much per kernel call, spread over its workers.
pub fn recording_cost_ns(calls: usize) -> f64 {
    let calls = calls.max(1);
    let rec = Recorder::new(1, calls, 0);
    let start = std::time::Instant::now();
    record_empty_calls(&rec, calls);
    start.elapsed().as_nanos() as f64 / calls as f64
}

/// Records `calls` calls of an empty kernel on `rec`, as density calls of step 1 whose
/// chunks start at 0, 1, 2, ….
fn record_empty_calls(rec: &Recorder, calls: usize) {
    let mut data = [0u8; 1];
    let empty = |_: usize, chunk: &mut [u8]| {
        std::hint::black_box(chunk);
    };
    for i in 0..calls {
        let phase = Phase::Pass(sph_solver::solver::Pass::Density);
        timed_call(rec, phase, 1, i, &mut data[..], &empty);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use sph_solver::solver::Pass;

    #[test]
    fn calibration_records_every_call_and_reports_a_positive_cost() {
        assert!(recording_cost_ns(1000) > 0.0);
        let rec = Recorder::new(1, 0, 0);
        record_empty_calls(&rec, 1000);
        let end = rec.now_ns();
        let trace = rec.finish(0, end, 1);
        assert_eq!(trace.kernels.len(), 1000);
        let mut firsts: Vec<usize> = trace.kernels.iter().map(|e| e.first).collect();
        firsts.sort_unstable();
        assert_eq!(firsts, (0..1000).collect::<Vec<_>>());
        for e in &trace.kernels {
            assert_eq!(
                (e.phase, e.step, e.len, e.worker),
                (Phase::Pass(Pass::Density), 1, 1, 0)
            );
            assert!(e.start_ns <= e.end_ns && e.end_ns <= end, "{e:?}");
        }
    }
}
