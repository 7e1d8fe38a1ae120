//! Where the events of a trace are kept while the strategy's threads run.
//!
//! **Workers.** A worker is a slot that one live thread holds at a time. The first time a
//! thread records for a [`Recorder`] it takes a free slot and keeps it until it exits (a
//! thread-local guard gives the slot back from the thread's exit path), so a pool's long-lived
//! threads keep one slot each for the whole run. A thread prefers the lowest free slot that no
//! other thread took during the same pass ([`Recorder::begin_pass`]), so `std-static`'s fresh
//! threads get slots `0..cores` in the order they first record in each pass — two lanes even
//! when the operating system happens to run them one after the other. Worker indices therefore
//! stay below the number of threads a pass uses at most, and the events of one slot never
//! overlap in time: a thread takes its slot before it reads the clock for its first call, and
//! gives it back only after its last.
//!
//! **Cost.** Per kernel call: one thread-local lookup, one reference-count increment, two
//! monotonic clock reads and one push onto the slot's own buffer under its mutex, which no
//! other thread takes while the run lasts (so it is never contended). Per pass: one atomic
//! increment. Nothing per particle. Each slot's buffer is preallocated and written once before
//! the run (no page faults while timing); a thread takes the slot table's lock only once, when
//! it first records.

use std::cell::RefCell;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex, MutexGuard, PoisonError};
use std::time::Instant;

use sph_solver::solver::Pass;
pub use sph_solver::solver::Phase;

/// One kernel call: which worker ran which chunk of which phase of which step, and when.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct KernelEvent {
    /// The pass (or rebuild) it belongs to.
    pub phase: Phase,
    /// 1-based step number.
    pub step: usize,
    /// Dense worker index (see the module documentation).
    pub worker: usize,
    /// The OS thread that ran the call: an index into [`Trace::threads`](super::Trace).
    pub thread: usize,
    /// Index of the chunk's first particle.
    pub first: usize,
    /// Number of particles in the chunk.
    pub len: usize,
    /// Start, nanoseconds since the trace's origin.
    pub start_ns: u64,
    /// End, nanoseconds since the trace's origin (`>= start_ns`).
    pub end_ns: u64,
}

impl KernelEvent {
    /// The call's duration in nanoseconds.
    pub fn duration_ns(&self) -> u64 {
        self.end_ns - self.start_ns
    }
}

/// Work that the thread driving the steps does between passes, on its own.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum SerialWork {
    /// Bringing the neighbour search up to date before the density pass (for the grid this
    /// span includes waiting for its `grid rebuild` kernel calls on the workers).
    Rebuild,
    /// Scanning the state for NaN or infinity after the last pass.
    Check,
}

impl SerialWork {
    /// Name, as in trace.json and the timeline's legend.
    pub fn as_str(self) -> &'static str {
        match self {
            SerialWork::Rebuild => "rebuild neighbours",
            SerialWork::Check => "divergence check",
        }
    }
}

/// One piece of serial work on the calling thread.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SerialEvent {
    /// What it was.
    pub work: SerialWork,
    /// 1-based step number.
    pub step: usize,
    /// Start, nanoseconds since the trace's origin.
    pub start_ns: u64,
    /// End, nanoseconds since the trace's origin (`>= start_ns`).
    pub end_ns: u64,
}

/// An OS thread that ran at least one kernel call.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ThreadInfo {
    /// The thread's name (`rayon-chunks-1`, `crossbeam-pool-0`, `main`), or `unnamed`.
    pub name: String,
    /// The worker slot it held.
    pub worker: usize,
}

/// Everything recorded during a traced run, with times relative to the start of the step loop.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Trace {
    /// Every kernel call, ordered by start time.
    pub kernels: Vec<KernelEvent>,
    /// The calling thread's serial work, ordered by start time.
    pub serial: Vec<SerialEvent>,
    /// The threads that ran kernel calls, in the order they first recorded.
    pub threads: Vec<ThreadInfo>,
    /// Number of worker tracks: at least the expected number of workers, and more than every
    /// recorded worker index.
    pub workers: usize,
    /// Duration of the step loop in nanoseconds; every event lies within `0..=wall_ns`.
    pub wall_ns: u64,
}

impl Trace {
    /// The phases this trace's rows and legends show, in step order: the grid's rebuild when
    /// it ran kernel calls, then the passes of the traced model (WCSPH's when any of its own
    /// passes ran, else Müller's), each even if it ran none.
    pub fn phases(&self) -> Vec<Phase> {
        let ran = |p: Phase| self.kernels.iter().any(|e| e.phase == p);
        let wcsph = Pass::WCSPH
            .iter()
            .any(|&p| !Pass::MUELLER.contains(&p) && ran(Phase::Pass(p)));
        let passes: &[Pass] = if wcsph { &Pass::WCSPH } else { &Pass::MUELLER };
        ran(Phase::Rebuild)
            .then_some(Phase::Rebuild)
            .into_iter()
            .chain(passes.iter().map(|&p| Phase::Pass(p)))
            .collect()
    }
}

type Buffer = Arc<Mutex<Vec<KernelEvent>>>;

/// Collects [`KernelEvent`]s from any number of threads and [`SerialEvent`]s from the caller.
#[derive(Debug)]
pub struct Recorder {
    id: u64,
    origin: Instant,
    shared: Arc<Shared>,
}

#[derive(Debug)]
struct Shared {
    pass: AtomicU64,
    slots: Mutex<Slots>,
    serial: Mutex<Vec<SerialEvent>>,
}

#[derive(Debug)]
struct Slots {
    held: Vec<bool>,
    /// The pass (see [`Recorder::begin_pass`]) in which each slot was last taken.
    taken_in: Vec<u64>,
    buffers: Vec<Buffer>,
    threads: Vec<ThreadInfo>,
    capacity: usize,
}

/// A thread's hold on a worker slot; gives the slot back when the thread exits (or when the
/// thread starts recording for another recorder).
struct Held {
    recorder: u64,
    slot: WorkerSlot,
    shared: Arc<Shared>,
}

impl Drop for Held {
    fn drop(&mut self) {
        lock(&self.shared.slots).held[self.slot.worker] = false;
    }
}

thread_local! {
    static HELD: RefCell<Option<Held>> = const { RefCell::new(None) };
}

/// The calling thread's worker slot in a [`Recorder`]: its index and its event buffer.
#[derive(Debug, Clone)]
pub struct WorkerSlot {
    /// Dense worker index.
    pub worker: usize,
    /// Index of the calling OS thread in the trace's thread list.
    pub thread: usize,
    buffer: Buffer,
}

impl WorkerSlot {
    /// Appends an event to this worker's buffer (an uncontended lock).
    pub fn push(&self, event: KernelEvent) {
        lock(&self.buffer).push(event);
    }
}

/// An empty buffer for `capacity` events whose memory has been written once, so that the
/// run does not pay the page faults of its first touch.
fn prefaulted(capacity: usize) -> Vec<KernelEvent> {
    let mut v = Vec::with_capacity(capacity);
    v.resize(
        capacity,
        KernelEvent {
            phase: Phase::Rebuild,
            step: 0,
            worker: 0,
            thread: 0,
            first: 0,
            len: 0,
            start_ns: 0,
            end_ns: 0,
        },
    );
    v.clear();
    v
}

fn lock<T>(m: &Mutex<T>) -> MutexGuard<'_, T> {
    // A panicking kernel never holds these locks; a poisoned one still holds whole events.
    m.lock().unwrap_or_else(PoisonError::into_inner)
}

impl Recorder {
    /// A recorder whose clock starts now, with `workers` slots whose buffers each hold
    /// `events_per_worker` events before they grow, and room for `serial_events` serial events.
    pub fn new(workers: usize, events_per_worker: usize, serial_events: usize) -> Self {
        static NEXT_ID: AtomicU64 = AtomicU64::new(0);
        let workers = workers.max(1);
        let buffers = (0..workers)
            .map(|_| Arc::new(Mutex::new(prefaulted(events_per_worker))))
            .collect();
        Recorder {
            id: NEXT_ID.fetch_add(1, Ordering::Relaxed),
            origin: Instant::now(),
            shared: Arc::new(Shared {
                pass: AtomicU64::new(0),
                slots: Mutex::new(Slots {
                    held: vec![false; workers],
                    taken_in: vec![u64::MAX; workers],
                    buffers,
                    threads: Vec::with_capacity(workers),
                    capacity: events_per_worker,
                }),
                serial: Mutex::new(Vec::with_capacity(serial_events)),
            }),
        }
    }

    /// Nanoseconds since the recorder was created (a monotonic clock).
    pub fn now_ns(&self) -> u64 {
        // u64 nanoseconds last 584 years.
        self.origin.elapsed().as_nanos() as u64
    }

    /// Marks the start of a pass: a thread that first records from now on prefers a slot that
    /// no thread took during this pass.
    pub fn begin_pass(&self) {
        self.shared.pass.fetch_add(1, Ordering::Relaxed);
    }

    /// The calling thread's worker slot, taking a free one on the thread's first call.
    pub fn worker(&self) -> WorkerSlot {
        HELD.with(|cell| {
            let mut held = cell.borrow_mut();
            if let Some(h) = held.as_ref().filter(|h| h.recorder == self.id) {
                return h.slot.clone();
            }
            // Give back a slot held for an earlier recorder before taking one here.
            *held = None;
            let slot = self.acquire();
            *held = Some(Held {
                recorder: self.id,
                slot: slot.clone(),
                shared: Arc::clone(&self.shared),
            });
            slot
        })
    }

    fn acquire(&self) -> WorkerSlot {
        let mut slots = lock(&self.shared.slots);
        let pass = self.shared.pass.load(Ordering::Relaxed);
        let free = |s: &Slots, w: usize| !s.held[w];
        let fresh = (0..slots.held.len()).find(|&w| free(&slots, w) && slots.taken_in[w] != pass);
        let any = (0..slots.held.len()).find(|&w| free(&slots, w));
        let worker = match fresh.or(any) {
            Some(w) => w,
            None => {
                // More threads at once than expected: add a slot rather than share one.
                let capacity = slots.capacity;
                slots.held.push(false);
                slots.taken_in.push(u64::MAX);
                slots
                    .buffers
                    .push(Arc::new(Mutex::new(Vec::with_capacity(capacity))));
                slots.held.len() - 1
            }
        };
        slots.held[worker] = true;
        slots.taken_in[worker] = pass;
        let name = std::thread::current()
            .name()
            .unwrap_or("unnamed")
            .to_owned();
        slots.threads.push(ThreadInfo { name, worker });
        WorkerSlot {
            worker,
            thread: slots.threads.len() - 1,
            buffer: Arc::clone(&slots.buffers[worker]),
        }
    }

    /// Records serial work done by the caller between `start_ns` and `end_ns`.
    pub fn record_serial(&self, work: SerialWork, step: usize, start_ns: u64, end_ns: u64) {
        lock(&self.shared.serial).push(SerialEvent {
            work,
            step,
            start_ns,
            end_ns,
        });
    }

    /// Collects every event once all kernel calls have returned, with times moved so that the
    /// step loop runs from 0 to `end_ns - start_ns`, and at least `workers` worker tracks.
    pub fn finish(self, start_ns: u64, end_ns: u64, workers: usize) -> Trace {
        let slots = lock(&self.shared.slots);
        let mut kernels: Vec<KernelEvent> = slots
            .buffers
            .iter()
            .flat_map(|b| std::mem::take(&mut *lock(b)))
            .collect();
        let mut serial = std::mem::take(&mut *lock(&self.shared.serial));
        let rebase = |t: u64| t.saturating_sub(start_ns);
        for e in &mut kernels {
            (e.start_ns, e.end_ns) = (rebase(e.start_ns), rebase(e.end_ns));
        }
        for e in &mut serial {
            (e.start_ns, e.end_ns) = (rebase(e.start_ns), rebase(e.end_ns));
        }
        kernels.sort_by_key(|e| (e.start_ns, e.worker));
        serial.sort_by_key(|e| e.start_ns);
        let observed = kernels.iter().map(|e| e.worker + 1).max().unwrap_or(0);
        Trace {
            kernels,
            serial,
            threads: slots.threads.clone(),
            workers: workers.max(observed),
            wall_ns: end_ns.saturating_sub(start_ns),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use sph_solver::solver::Pass;

    fn event(slot: &WorkerSlot, first: usize) -> KernelEvent {
        KernelEvent {
            phase: Phase::Pass(Pass::Density),
            step: 1,
            worker: slot.worker,
            thread: slot.thread,
            first,
            len: 1,
            start_ns: 10,
            end_ns: 20,
        }
    }

    #[test]
    fn a_thread_keeps_its_slot_and_other_threads_get_the_next_free_ones() {
        let rec = Recorder::new(2, 4, 0);
        let a = rec.worker();
        assert_eq!(rec.worker().worker, a.worker);
        let b = std::thread::scope(|s| s.spawn(|| rec.worker()).join().unwrap());
        assert_ne!(a.worker, b.worker);
        assert!(a.worker < 2 && b.worker < 2);
    }

    #[test]
    fn a_thread_that_exits_gives_its_slot_to_the_next_thread() {
        let rec = Recorder::new(1, 4, 0);
        for _ in 0..3 {
            let slot = std::thread::scope(|s| s.spawn(|| rec.worker()).join().unwrap());
            assert_eq!(slot.worker, 0);
        }
        let trace = rec.finish(0, 0, 1);
        assert_eq!(trace.threads.len(), 3);
        assert_eq!(trace.workers, 1);
    }

    #[test]
    fn threads_that_run_one_after_another_in_a_pass_get_their_own_slots() {
        let rec = Recorder::new(2, 4, 0);
        for _ in 0..3 {
            rec.begin_pass();
            let slots: Vec<usize> = (0..2)
                .map(|_| std::thread::scope(|s| s.spawn(|| rec.worker().worker).join().unwrap()))
                .collect();
            assert_eq!(slots, [0, 1]);
        }
    }

    #[test]
    fn finish_collects_every_worker_s_events_in_time_order_relative_to_the_start() {
        let rec = Recorder::new(2, 4, 1);
        let a = rec.worker();
        a.push(KernelEvent {
            start_ns: 50,
            end_ns: 60,
            ..event(&a, 5)
        });
        std::thread::scope(|s| {
            s.spawn(|| {
                let b = rec.worker();
                b.push(event(&b, 0));
            });
        });
        rec.record_serial(SerialWork::Check, 1, 70, 80);
        let trace = rec.finish(10, 100, 2);
        let firsts: Vec<_> = trace.kernels.iter().map(|e| e.first).collect();
        assert_eq!(firsts, [0, 5]);
        assert_eq!(
            (trace.kernels[0].start_ns, trace.kernels[0].end_ns),
            (0, 10)
        );
        assert_eq!(trace.serial[0].start_ns, 60);
        assert_eq!(trace.wall_ns, 90);
        assert_eq!(
            trace.threads[0].name,
            std::thread::current().name().unwrap()
        );
    }

    #[test]
    fn a_new_recorder_hands_a_thread_a_fresh_slot() {
        let first = Recorder::new(1, 1, 0);
        let _ = first.worker();
        let second = Recorder::new(1, 1, 0);
        assert_eq!(second.worker().worker, 0);
        assert_eq!(second.finish(0, 0, 1).threads.len(), 1);
    }
}
