//! Waking a strategy's threads before a run is timed.
//!
//! A thread that has slept for a while does not get its core back at once on a virtual
//! machine. On the project's 2-core VM, a `crossbeam-pool` run at N = 10⁶ started after the
//! single-threaded build of its state: for its first 30–80 ms the second thread took each
//! pass 2–4 ms late, or ran a fraction of the pass (its threads' CPU time read 1.0–1.4
//! cores over those windows), and then 2.0 cores for the rest of the run. A 10-step run of
//! 0.45 s lost about a tenth of its time to that start, which `seq`, on the thread that built
//! the state, never pays, and with the time charged to the strategy the efficiency read low.
//!
//! So before the timed steps, [`wake`] runs short passes whose kernel calls each spin for
//! [`SPIN`], until the passes have taken no more than half again their time on all cores for
//! [`SETTLED`] in a row, or until [`LONGEST`] has passed (a machine whose cores are taken
//! stays slow: the run then goes on and says so as it would without the wake). On a quiet
//! machine it costs about [`SETTLED`]. It computes nothing the run reads.

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::time::{Duration, Instant};

use crate::{Config, Executor, Info, KernelPanic};

/// How long each kernel call of a waking pass spins.
pub const SPIN: Duration = Duration::from_micros(500);
/// Allowed beyond half again a pass's time on all cores, for the cost of the pass itself
/// (`std-static` starts its threads on every pass).
pub const SLACK: Duration = Duration::from_micros(200);
/// How long in a row the waking passes must run on all cores.
pub const SETTLED: Duration = Duration::from_millis(10);
/// The longest a wake lasts.
pub const LONGEST: Duration = Duration::from_millis(150);

/// The longest a kernel call of [`rouse`]'s pass waits for the others.
pub const ROUSE_LONGEST: Duration = Duration::from_millis(1);

/// Brings a strategy's sleeping threads back before a pass that is about to be timed: one
/// pass over one element per thread of `exec`, whose kernel calls each wait, spinning, until
/// all the pass's calls have begun, or for at most [`ROUSE_LONGEST`]. The calls are as many
/// as `info` promises for `config` ([`Info::kernel_calls`]; one per element for a strategy
/// that promises no number), so every thread that takes a call stays in the pass until the
/// last one has come, and they leave it together, awake.
///
/// Returns whether every call came in time. A thread that slept through [`ROUSE_LONGEST`]
/// is still waking when the timed pass starts, as without the rouse. Computes nothing the
/// run reads; nothing to do for an executor of one thread.
pub fn rouse<E: Executor>(exec: &E, info: &Info, config: &Config) -> Result<bool, KernelPanic> {
    let len = exec.threads();
    let calls = info.kernel_calls(len, config).unwrap_or(len);
    if len < 2 || calls < 2 {
        return Ok(true);
    }
    let (arrived, late) = (AtomicUsize::new(0), AtomicBool::new(false));
    let mut cells = vec![0u8; len];
    exec.for_each_chunk(&mut cells[..], |_, _| {
        arrived.fetch_add(1, Ordering::AcqRel);
        let start = Instant::now();
        while arrived.load(Ordering::Acquire) < calls {
            if start.elapsed() > ROUSE_LONGEST {
                late.store(true, Ordering::Relaxed);
                break;
            }
            std::hint::spin_loop();
        }
    })?;
    Ok(!late.into_inner())
}

/// What a wake found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Woken {
    /// How long it took.
    pub elapsed: Duration,
    /// Whether the passes ran on all cores for [`SETTLED`] in a row before [`LONGEST`].
    pub settled: bool,
}

/// Runs waking passes on `exec` (see the module's docs) until its threads run on `cores`
/// cores at once: the smaller of its threads and the CPUs they may use, since more threads
/// than CPUs can never run at once. Nothing to do for an executor of one thread or one core.
pub fn wake<E: Executor>(exec: &E, cores: usize) -> Result<Woken, KernelPanic> {
    let times = Times {
        spin: SPIN,
        slack: SLACK,
        settled: SETTLED,
        longest: LONGEST,
    };
    wake_with(exec, cores, times)
}

/// [`wake`] with its times given (tests shorten them).
fn wake_with<E: Executor>(exec: &E, cores: usize, times: Times) -> Result<Woken, KernelPanic> {
    let cores = cores.min(exec.threads());
    if cores < 2 {
        return Ok(Woken {
            elapsed: Duration::ZERO,
            settled: true,
        });
    }
    let mut settling = Settling::new(Instant::now());
    let mut cells = vec![0u8; 4 * cores];
    loop {
        let (calls, pass) = (AtomicUsize::new(0), Instant::now());
        exec.for_each_chunk(&mut cells[..], |_, _| {
            calls.fetch_add(1, Ordering::Relaxed);
            let t = Instant::now();
            while t.elapsed() < times.spin {
                std::hint::spin_loop();
            }
        })?;
        let now = Instant::now();
        let fast = on_all_cores(now - pass, calls.into_inner(), cores, times);
        if let Some(woken) = settling.after_pass(pass, now, fast, times) {
            return Ok(woken);
        }
    }
}

/// The times of a wake.
#[derive(Debug, Clone, Copy)]
struct Times {
    spin: Duration,
    slack: Duration,
    settled: Duration,
    longest: Duration,
}

/// Whether a pass of `calls` kernel calls of `times.spin` each, which took `took`, ran on
/// `cores` cores: within half again the time of its calls spread over them, plus the slack.
fn on_all_cores(took: Duration, calls: usize, cores: usize, times: Times) -> bool {
    let rounds = u32::try_from(calls.div_ceil(cores.max(1))).unwrap_or(u32::MAX);
    took <= times.spin.saturating_mul(rounds).saturating_mul(3) / 2 + times.slack
}

/// A wake's progress: when it started, and since when its passes have run on all cores.
struct Settling {
    start: Instant,
    fast_since: Option<Instant>,
}

impl Settling {
    fn new(start: Instant) -> Settling {
        Settling {
            start,
            fast_since: None,
        }
    }

    /// Takes in a pass that began at `pass` and ended at `now` (`fast`: on all cores); the
    /// wake's outcome once it is over.
    fn after_pass(
        &mut self,
        pass: Instant,
        now: Instant,
        fast: bool,
        times: Times,
    ) -> Option<Woken> {
        if !fast {
            self.fast_since = None;
        } else if now - *self.fast_since.get_or_insert(pass) >= times.settled {
            return Some(self.done(now, true));
        }
        (now - self.start >= times.longest).then(|| self.done(now, false))
    }

    fn done(&self, now: Instant, settled: bool) -> Woken {
        Woken {
            elapsed: now - self.start,
            settled,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::seq::SeqExecutor;

    const MS: Duration = Duration::from_millis(1);
    const TIMES: Times = Times {
        spin: Duration::from_micros(500),
        slack: Duration::from_micros(200),
        settled: Duration::from_millis(10),
        longest: Duration::from_millis(150),
    };

    #[test]
    fn one_thread_or_one_core_needs_no_wake() {
        let woken = wake(&SeqExecutor, 8).unwrap();
        assert_eq!((woken.elapsed, woken.settled), (Duration::ZERO, true));
    }

    #[test]
    fn a_pass_is_on_all_cores_within_half_again_its_calls_spread_over_them() {
        let times = TIMES;
        // 8 calls on 2 cores: 4 rounds, 2 ms; one core alone takes 4 ms.
        assert_eq!((SPIN, SLACK), (TIMES.spin, TIMES.slack));
        assert!(on_all_cores(2 * MS, 8, 2, times));
        assert!(on_all_cores(3 * MS + MS / 5, 8, 2, times));
        assert!(!on_all_cores(3 * MS + MS / 4, 8, 2, times));
        assert!(!on_all_cores(4 * MS, 8, 2, times), "one core of two");
        // 5 calls on 2 cores: 3 rounds, 1.5 ms.
        assert!(on_all_cores(2 * MS, 5, 2, times));
        assert!(!on_all_cores(3 * MS, 5, 2, times));
        // std-static: a call per thread, 0.5 ms; one core takes 1 ms.
        assert!(on_all_cores(MS * 9 / 10, 2, 2, times));
        assert!(!on_all_cores(MS, 2, 2, times));
    }

    #[test]
    fn a_rouse_keeps_each_call_until_all_have_come_and_gives_up_on_a_thread_that_never_does() {
        let config = crate::Config::new(2, 8);
        let info = <crate::crossbeam_pool::CrossbeamPool as crate::Strategy>::INFO;
        assert!(rouse(&SeqExecutor, &info, &config).unwrap(), "one thread");
        // Both calls on the caller, one after the other: the first waits out its limit.
        let start = Instant::now();
        assert!(!rouse(&Serial, &info, &config).unwrap());
        assert!(start.elapsed() >= ROUSE_LONGEST);
        // A real pool: both threads come (a loaded machine may need more than one try).
        struct Rousing(crate::Config);
        impl crate::Session for Rousing {
            type Output = bool;
            fn run<E: Executor>(self, exec: &E) -> bool {
                let info = <crate::crossbeam_pool::CrossbeamPool as crate::Strategy>::INFO;
                (0..100).any(|_| rouse(exec, &info, &self.0).unwrap())
            }
        }
        let pool = <crate::crossbeam_pool::CrossbeamPool as crate::Strategy>::build(&config);
        assert!(crate::Strategy::run(&pool.unwrap(), Rousing(config)).unwrap());
    }

    /// Claims two threads and runs every call on the caller, one after the other.
    struct Serial;

    impl Executor for Serial {
        fn for_each_chunk<O, F>(&self, out: O, kernel: F) -> Result<(), KernelPanic>
        where
            O: crate::Split,
            F: Fn(usize, O) + Sync,
        {
            for (first, chunk) in crate::balanced_chunks(out, 8) {
                kernel(first, chunk);
            }
            Ok(())
        }
        fn threads(&self) -> usize {
            2
        }
    }

    #[test]
    fn passes_on_all_cores_for_the_settled_time_in_a_row_end_the_wake() {
        let t0 = Instant::now();
        let at = |ms: u32| t0 + ms * MS;
        let mut s = Settling::new(t0);
        // Slow, then fast passes of 2 ms from 4 ms on; one slow pass in between starts over.
        assert_eq!(s.after_pass(at(0), at(4), false, TIMES), None);
        assert_eq!(s.after_pass(at(4), at(6), true, TIMES), None);
        assert_eq!(s.after_pass(at(6), at(12), true, TIMES), None);
        assert_eq!(s.after_pass(at(12), at(16), false, TIMES), None);
        assert_eq!(s.after_pass(at(16), at(18), true, TIMES), None);
        assert_eq!(s.after_pass(at(18), at(24), true, TIMES), None);
        let woken = s.after_pass(at(24), at(26), true, TIMES).unwrap();
        assert_eq!((woken.elapsed, woken.settled), (26 * MS, true));
    }

    #[test]
    fn a_wake_that_never_settles_gives_up_after_the_longest_time() {
        let t0 = Instant::now();
        let mut s = Settling::new(t0);
        for ms in (0..145u32).step_by(5) {
            assert_eq!(
                s.after_pass(t0 + ms * MS, t0 + (ms + 5) * MS, ms % 10 == 0, TIMES),
                None
            );
        }
        let woken = s
            .after_pass(t0 + 150 * MS, t0 + 155 * MS, false, TIMES)
            .unwrap();
        assert!(!woken.settled);
        assert_eq!(woken.elapsed, 155 * MS);
    }

    #[test]
    fn a_wake_on_threads_sharing_one_core_gives_up_and_one_judged_on_one_core_needs_none() {
        /// Claims two threads and runs every call on the caller: cores all taken. Counts its
        /// passes.
        #[derive(Default)]
        struct Taken {
            passes: std::cell::Cell<usize>,
        }
        impl Executor for Taken {
            fn for_each_chunk<O, F>(&self, out: O, kernel: F) -> Result<(), KernelPanic>
            where
                O: crate::Split,
                F: Fn(usize, O) + Sync,
            {
                self.passes.set(self.passes.get() + 1);
                for (first, chunk) in crate::balanced_chunks(out, 8) {
                    kernel(first, chunk);
                }
                Ok(())
            }
            fn threads(&self) -> usize {
                2
            }
        }
        let times = Times {
            spin: MS / 10,
            slack: Duration::ZERO,
            settled: 2 * MS,
            longest: 20 * MS,
        };
        let taken = Taken::default();
        let woken = wake_with(&taken, 2, times).unwrap();
        assert!(!woken.settled && woken.elapsed >= 20 * MS, "{woken:?}");
        assert!(taken.passes.get() > 1);
        // Judged as one core (the CPUs it may use), the same executor needs no wake.
        let alone = Taken::default();
        assert!(wake_with(&alone, 1, times).unwrap().settled);
        assert_eq!(alone.passes.get(), 0);
    }
}
