//! The CPU time of a pool's own threads, read up to date from the session's thread.
//!
//! `getrusage` and the process's CPU clock add up each thread's CPU time as the scheduler last
//! accounted it, and a thread running on another core is accounted only at the timer tick
//! (every 4 ms on the project's 2-core VM): over a window of a few milliseconds the process's
//! CPU time moves in whole ticks. `crossbeam-pool` judges whether its threads get their cores
//! from windows that short (see `degrade`), and with the process's CPU time a quiet 2-core run
//! at N = 10⁶ read as one core often enough that 3 runs of 40 ran their passes alone for
//! nothing (0.67–0.75 s instead of 0.37–0.50).
//!
//! A thread's own CPU clock, read from any thread of the process, is brought up to date at
//! the read: the kernel first accounts the slice the thread is running. So each of the pool's
//! threads names its clock when it starts ([`ThreadClocks::register`], from its thread id:
//! Linux numbers a thread's CPU clock as `pthread_getcpuclockid` does, `(!tid << 3) | 6`), and
//! the session's thread adds them up ([`ThreadClocks::total`]): one system call per thread,
//! made only when a window opens or closes. Threads outside the pool (the caller waiting for
//! the session) are not counted, which is what the judgement asks about.
//!
//! Where those clocks cannot be read (another operating system, or a sandbox that refuses the
//! clock ids), the pool falls back to the process's CPU time for the rest of the run, once,
//! so that no window mixes the two.

use std::sync::OnceLock;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use nix::time::ClockId;

/// Flags of a thread's CPU clock id in Linux's numbering (`include/linux/posix-timers.h`):
/// `CPUCLOCK_PERTHREAD_MASK` (the id names a thread, not a process) and `CPUCLOCK_SCHED` (the
/// scheduler's precise run time, not the tick-sampled user + system time).
#[cfg(target_os = "linux")]
const PER_THREAD_SCHED: i32 = 4 | 2;

/// The CPU clocks of a fixed number of threads, each named by its thread once it has started.
#[derive(Debug)]
pub(crate) struct ThreadClocks {
    clocks: Vec<OnceLock<ClockId>>,
    /// A clock could not be read: the process's CPU time is used from then on.
    fallback: AtomicBool,
}

impl ThreadClocks {
    /// Room for `threads` threads, none registered yet.
    pub(crate) fn new(threads: usize) -> Self {
        ThreadClocks {
            clocks: (0..threads).map(|_| OnceLock::new()).collect(),
            fallback: AtomicBool::new(false),
        }
    }

    /// Names the calling thread's CPU clock as thread `index`'s (the first registration of
    /// an index counts; an index out of range is ignored).
    pub(crate) fn register(&self, index: usize) {
        if let Some(slot) = self.clocks.get(index) {
            let _ = slot.set(own_clock());
        }
    }

    /// The CPU time (user + system) the registered threads have used so far, up to date;
    /// `None` while some thread has not registered yet, and once when a clock cannot be read
    /// (from then on, the process's CPU time, so that no window mixes the two).
    pub(crate) fn total(&self) -> Option<Duration> {
        if self.clocks.iter().any(|slot| slot.get().is_none()) {
            return None;
        }
        if self.fallback.load(Ordering::Relaxed) {
            return process_cpu_time();
        }
        let total = self.clocks.iter().try_fold(Duration::ZERO, |sum, slot| {
            let t = slot.get()?.now().ok()?;
            let used = Duration::new(t.tv_sec().try_into().ok()?, t.tv_nsec().try_into().ok()?);
            Some(sum + used)
        });
        if total.is_none() {
            self.fallback.store(true, Ordering::Relaxed);
        }
        total
    }
}

/// The calling thread's CPU clock, as other threads of the process can read it: on Linux the
/// id `pthread_getcpuclockid` gives, from the thread id.
#[cfg(target_os = "linux")]
fn own_clock() -> ClockId {
    ClockId::from_raw(((!nix::unistd::gettid().as_raw()) << 3) | PER_THREAD_SCHED)
}

/// Elsewhere, an id that reads as unreadable, so that the process's CPU time is used.
#[cfg(not(target_os = "linux"))]
fn own_clock() -> ClockId {
    ClockId::from_raw(-1)
}

/// CPU time (user + system) of the whole process so far, as the kernel accounted it.
fn process_cpu_time() -> Option<Duration> {
    use nix::sys::resource::{UsageWho, getrusage};
    let usage = getrusage(UsageWho::RUSAGE_SELF).ok()?;
    let secs =
        |t: nix::sys::time::TimeVal| Duration::new(t.tv_sec() as u64, t.tv_usec() as u32 * 1000);
    Some(secs(usage.user_time()) + secs(usage.system_time()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::atomic::{AtomicU64, Ordering};
    use std::time::Instant;

    /// The calling thread's own CPU time, as it reads it itself.
    fn own_cpu_time() -> Duration {
        let t = ClockId::CLOCK_THREAD_CPUTIME_ID
            .now()
            .expect("own CPU clock");
        Duration::new(t.tv_sec() as u64, t.tv_nsec() as u32)
    }

    #[test]
    fn the_total_is_none_until_every_thread_has_registered() {
        let clocks = ThreadClocks::new(2);
        assert_eq!(clocks.total(), None);
        clocks.register(0);
        assert_eq!(clocks.total(), None);
        clocks.register(7); // out of range: ignored
        assert_eq!(clocks.total(), None);
        let registered = std::sync::Barrier::new(2);
        std::thread::scope(|s| {
            s.spawn(|| {
                clocks.register(1);
                registered.wait();
                registered.wait(); // alive until the total has been read
            });
            registered.wait();
            assert!(clocks.total().is_some());
            registered.wait();
        });
    }

    #[test]
    fn a_clock_that_cannot_be_read_gives_way_to_the_process_cpu_time_for_good() {
        let clocks = ThreadClocks::new(1);
        clocks.clocks[0].set(ClockId::from_raw(-1)).unwrap(); // not a clock
        assert_eq!(
            clocks.total(),
            None,
            "the window that would mix the two is not opened"
        );
        let first = clocks.total().expect("the process's CPU time");
        assert!(clocks.total().expect("still") >= first);
    }

    #[test]
    fn another_threads_cpu_time_is_read_up_to_date_while_it_runs() {
        // A thread reads its own CPU time (which brings its accounting up to date), then
        // computes without a system call for 200 µs of wall time and says so. Read from here
        // after that, its CPU time must have moved past its own reading. Tick-accounted CPU
        // time (`getrusage`, the process's clock) stays at that reading until the next tick
        // (4 ms) or context switch, so it fails this in nearly every round.
        let clocks = ThreadClocks::new(1);
        let (own, round, seen) = (AtomicU64::new(0), AtomicU64::new(0), AtomicU64::new(0));
        const ROUNDS: u64 = 50;
        std::thread::scope(|s| {
            s.spawn(|| {
                clocks.register(0);
                for r in 1..=ROUNDS {
                    own.store(own_cpu_time().as_nanos() as u64, Ordering::Relaxed);
                    let start = Instant::now();
                    while start.elapsed() < Duration::from_micros(200) {
                        std::hint::spin_loop();
                    }
                    round.store(r, Ordering::Release);
                    // Spinning, not yielding: a yield would bring the accounting up to date.
                    while seen.load(Ordering::Acquire) < r {
                        std::hint::spin_loop();
                    }
                }
            });
            for r in 1..=ROUNDS {
                while round.load(Ordering::Acquire) < r {
                    std::hint::spin_loop();
                }
                let total = clocks.total().map(|t| t.as_nanos() as u64);
                let before = own.load(Ordering::Relaxed);
                // Release the thread whatever the outcome, so that a failure cannot hang.
                seen.store(
                    if total > Some(before) { r } else { u64::MAX },
                    Ordering::Release,
                );
                assert!(
                    total > Some(before),
                    "round {r}: read {total:?} ns, no more than the thread's own {before} ns"
                );
            }
        });
    }
}
