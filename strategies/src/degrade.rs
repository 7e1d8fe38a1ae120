//! When `crossbeam-pool` stops asking for help: graceful degradation on shared cores.
//!
//! On a machine where another process keeps cores busy, the pool's threads do not get the
//! cores they were started for: two of them may take turns on one core, or one may be
//! descheduled in the middle of a chunk and hold the pass up for a scheduling round. Then
//! every pass still pays for its rendezvous and its hand-overs, and gains nothing: a 2-core
//! run beside one busy process was slower than the same strategy on 1 core.
//!
//! So the session's thread measures what its threads actually get. Over a window (at least
//! [`WINDOW`] of wall time, of which at least [`MIN_IN_PASSES`] inside passes) it compares
//! the CPU time of the pool's threads (each read from its own clock, up to date: see
//! `thread_clocks`) with the time spent inside passes: a pool of p threads on p free
//! cores uses about p CPU-seconds per second of pass (waiting threads spin or yield, which
//! counts), and one CPU-second per second of the serial work between passes (the session's
//! thread alone, the workers asleep), so the CPU time beyond the serial work, divided by the
//! time in passes, falling short of p by more than [`SHORTFALL`] means the cores are
//! shared (p: the threads the passes' chunks keep busy, and the pool runs alone only below
//! [`ALONE_BELOW`] cores' worth; both below). Once two windows in a row are short, the next passes run on the session's thread
//! alone (the workers sleep and leave their cores to the competing work): [`FIRST_SOLO`]
//! passes or [`FIRST_SOLO_TIME`], whichever ends first, both doubling while the shortfall
//! persists, up to [`MAX_SOLO`] passes; then a window asks for help again, and a window
//! without shortfall ends the degradation. The time bound matters for long passes: at
//! N = 10⁶ a pass takes 5–40 ms, and 64 passes alone were the rest of a 10-step run after a
//! stall of a few milliseconds; now such a stall costs a pass or two. p counts at most the
//! CPUs the pool's threads may use (the machine's, or under a placement the CPUs it pins them
//! to), so deliberate oversubscription (more threads than cores) is not mistaken for a busy
//! machine.
//!
//! The passes that wake a run's threads before it is timed (`wake`) are forgotten
//! ([`Degrade::forget`]): a late thread there is the start-up they absorb.
//!
//! A pass that starts more than the workers' spinning time ([`spin_wait::LIMIT`]) after the
//! last parallel pass wakes workers that have gone to sleep, and waking a sleeping thread on
//! a virtual machine can take a good part of a short pass: the first [`WAKE_ALLOWANCE`] of
//! such a pass counts as serial work (one CPU-second per second), the rest as a pass.
//! Otherwise a large run, whose serial work between steps (the grid's counting sort)
//! outlasts the spinning, found a shortfall on a quiet 2-core VM in about one run in four at
//! N = 10⁶ and ran all its passes alone. Only the allowance is discounted, so a long cold pass
//! on shared cores is still judged.
//!
//! A pass cannot use more threads than its chunks keep busy: k equal chunks on p threads take
//! ⌈k/p⌉ rounds, so the pass holds k/⌈k/p⌉ threads' worth of work ([`parallelism`]; 16 chunks
//! on 12 threads: two rounds, 8 threads' worth), and the threads without a chunk soon sleep.
//! Each pass is measured against that, not against p. Measured against p, a quiet 16-core
//! machine ran 20 of the 30 passes of a 10-step run at N = 10⁶ alone with 16 chunks on 12 or
//! 16 threads (and said that other work had taken the cores), and a quiet 2-core one ran
//! every pass alone with 1 chunk and a few with 3. A pass of one chunk has no help to give up
//! and is not judged.
//!
//! And running alone pays only when the pool gets little more than what one thread alone
//! gets, one core's worth: the pool runs alone only below [`ALONE_BELOW`] (1.5) cores' worth,
//! whatever its size. On two threads that is the shortfall above; on more it is far below it.
//! Judged by the shortfall alone, even measured against its chunks, a pool of 16 threads on a
//! quiet 16-core machine (chunks of unequal work: the threads done first sleep until the pass
//! ends) ran 15–20 of a 10-step run's passes alone at N = 10⁶ with 16 and 64 chunks, and took
//! 0.18–0.40 s where 256 chunks, no pass alone, took 0.11 s.
//!
//! One short window alone is not enough, because a quiet machine has short moments too: the
//! first window of a run at N = 10⁶ (the first touches of the warm-up's memory), a page-fault
//! storm, the virtual machine's host taking a core for a few milliseconds, a program starting
//! beside the run. Each read as 1.2–1.7 cores on the quiet 2-core VM, in about one run in
//! six, and the 64 passes alone that followed (before the time bound above) were the rest of
//! a 10-step run. Real contention lasts: it is found one window later.
//!
//! The results are the same bits either way: every chunk is computed by the same kernel on
//! the same data, whichever thread runs it. On a quiet machine the pool keeps its cores busy
//! and nothing changes.

use std::time::{Duration, Instant};

/// The shortest window whose CPU time is compared with its wall time.
pub(crate) const WINDOW: Duration = Duration::from_millis(5);
/// The least time inside passes a window must hold to be judged.
pub(crate) const MIN_IN_PASSES: Duration = Duration::from_millis(2);
/// How many cores' worth of CPU time may be missing from what the passes' chunks could keep
/// busy ([`parallelism`]) before a window is short (and then only below [`ALONE_BELOW`]).
pub(crate) const SHORTFALL: f64 = 0.5;
/// The pool runs alone only when its passes get less than this many cores' worth of CPU time,
/// however many threads they had work for: alone, the session's thread gets one core's worth,
/// without hand-overs and without waiting for a descheduled thread; a pool that gets more is
/// faster than that (see the module's docs).
pub(crate) const ALONE_BELOW: f64 = 2.0 - SHORTFALL;
/// How much of a pass that wakes sleeping workers counts as serial work.
/// (1 ms still misfired in 6 runs of 8 at N = 10⁶ on the 2-core VM: its wake-ups can take
/// milliseconds, and a short pass may end before the worker arrives.)
pub(crate) const WAKE_ALLOWANCE: Duration = Duration::from_millis(5);
/// Passes run alone after the first short window (at most: see [`FIRST_SOLO_TIME`]).
pub(crate) const FIRST_SOLO: u32 = 64;
/// The longest time the first passes alone last: when it has passed, the next pass asks for
/// help again however few passes ran alone. Periods of passes alone double together with
/// their pass count.
pub(crate) const FIRST_SOLO_TIME: Duration = Duration::from_millis(20);
/// The most passes run alone before help is asked for again.
pub(crate) const MAX_SOLO: u32 = 4096;

/// How many of `threads` threads a pass of `chunks` equal chunks keeps busy: the chunks over
/// the rounds they take (see the module's docs).
pub(crate) fn parallelism(threads: usize, chunks: usize) -> f64 {
    let (threads, chunks) = (threads.max(1), chunks.max(1));
    chunks as f64 / chunks.div_ceil(threads) as f64
}

/// Whether passes that used `cpu` over `wall`, with work for `parallelism` threads (at most
/// the CPUs they may use), fell so short of their cores that one thread alone would do as
/// well: less than `parallelism` − [`SHORTFALL`] cores' worth, and less than [`ALONE_BELOW`].
pub(crate) fn short_of_cores(parallelism: f64, cpu: Duration, wall: Duration) -> bool {
    if parallelism <= 1.0 || wall.is_zero() {
        return false;
    }
    cpu.as_secs_f64() / wall.as_secs_f64() < (parallelism - SHORTFALL).min(ALONE_BELOW)
}

/// A measuring window: when it started, the CPU time then, the time spent inside passes
/// since, and the thread-time those passes had work for (each pass's time × its
/// [`parallelism`]).
#[derive(Debug, Clone, Copy)]
struct Window {
    wall: Instant,
    cpu: Duration,
    in_passes: Duration,
    work: Duration,
}

/// The degradation state of one session (used by its thread only).
#[derive(Debug, Clone)]
pub(crate) struct Degrade {
    /// Pool threads that can run at once: min(cores, the CPUs they may use).
    threads: usize,
    /// Passes still to run alone.
    left: u32,
    /// When the passes alone end at the latest (meaningful while `left > 0`).
    until: Instant,
    /// The length of the last solo period (0: not degraded).
    span: u32,
    /// The last window was short, the one before it was not: one more short window and the
    /// pool runs alone.
    suspect: bool,
    /// The window being measured (`None`: start one at the next pass with help).
    window: Option<Window>,
    /// Passes run alone so far.
    solo_total: u64,
    /// When the last parallel pass ended (`None`: none yet).
    last_end: Option<Instant>,
    /// Whether the pass now running woke sleeping workers (see the module's docs).
    cold: bool,
}

impl Degrade {
    /// The state of a pool of `cores` threads that may use `cpus` CPUs.
    pub(crate) fn new(cores: usize, cpus: usize) -> Degrade {
        Degrade {
            threads: cores.min(cpus),
            left: 0,
            until: Instant::now(),
            span: 0,
            suspect: false,
            window: None,
            solo_total: 0,
            last_end: None,
            cold: true,
        }
    }

    /// Whether the next pass runs on the session's thread alone (and counts it).
    pub(crate) fn solo_pass(&mut self) -> bool {
        self.left > 0 && self.solo_pass_at(Instant::now())
    }

    /// [`Degrade::solo_pass`] at the instant `now` (tests give their own clock).
    fn solo_pass_at(&mut self, now: Instant) -> bool {
        if self.left == 0 {
            return false;
        }
        if now >= self.until {
            self.left = 0;
            return false;
        }
        self.left -= 1;
        self.solo_total += 1;
        true
    }

    /// Called before a pass with help, with the pool's threads' CPU time (read only when a window
    /// starts or ends).
    pub(crate) fn before_parallel_pass(&mut self, cpu_now: impl Fn() -> Option<Duration>) {
        self.before_parallel_pass_at(Instant::now(), cpu_now);
    }

    /// [`Degrade::before_parallel_pass`] at the instant `now` (tests give their own clock).
    fn before_parallel_pass_at(&mut self, now: Instant, cpu_now: impl Fn() -> Option<Duration>) {
        if self.threads < 2 {
            return;
        }
        self.cold = self
            .last_end
            .is_none_or(|end| now - end > crate::spin_wait::LIMIT);
        match self.window {
            None => {
                self.window = cpu_now().map(|cpu| Window {
                    wall: now,
                    cpu,
                    in_passes: Duration::ZERO,
                    work: Duration::ZERO,
                });
            }
            Some(w) if now - w.wall >= WINDOW && w.in_passes >= MIN_IN_PASSES => {
                self.window = None;
                let Some(cpu) = cpu_now() else { return };
                let wall = now - w.wall;
                // The serial work between passes ran on one thread.
                let serial = wall.saturating_sub(w.in_passes);
                let in_passes_cpu = cpu.saturating_sub(w.cpu).saturating_sub(serial);
                let parallelism = w.work.as_secs_f64() / w.in_passes.as_secs_f64();
                self.decide_at(now, in_passes_cpu, w.in_passes, parallelism);
            }
            Some(_) => {}
        }
    }

    /// Called after a pass with help of `chunks` chunks that took `elapsed`.
    pub(crate) fn after_parallel_pass(&mut self, elapsed: Duration, chunks: usize) {
        self.after_parallel_pass_at(Instant::now(), elapsed, chunks);
    }

    /// [`Degrade::after_parallel_pass`] at the instant `now`.
    fn after_parallel_pass_at(&mut self, now: Instant, elapsed: Duration, chunks: usize) {
        self.last_end = Some(now);
        let counted = if self.cold {
            elapsed.saturating_sub(WAKE_ALLOWANCE)
        } else {
            elapsed
        };
        if let Some(w) = &mut self.window {
            w.in_passes += counted;
            w.work += counted.mul_f64(parallelism(self.threads, chunks));
        }
    }

    /// Ends a window whose passes used `cpu` over `wall` with work for `parallelism` threads,
    /// at the instant `now`. A short window right after one that was not short only raises a
    /// suspicion: the pool runs alone once a second window in a row is short too (see the
    /// module's docs).
    fn decide_at(&mut self, now: Instant, cpu: Duration, wall: Duration, parallelism: f64) {
        if !short_of_cores(parallelism, cpu, wall) {
            (self.span, self.suspect) = (0, false);
        } else if self.span == 0 && !self.suspect {
            self.suspect = true;
        } else {
            self.suspect = false;
            self.span = (self.span * 2).clamp(FIRST_SOLO, MAX_SOLO);
            self.left = self.span;
            self.until = now + FIRST_SOLO_TIME * (self.span / FIRST_SOLO);
        }
    }

    /// Starts judging afresh, as a new pool would, but keeps the count of passes run alone.
    pub(crate) fn forget(&mut self) {
        *self = Degrade {
            solo_total: self.solo_total,
            ..Degrade::new(self.threads, self.threads)
        };
    }

    /// Pool threads that can run at once.
    #[cfg(test)]
    pub(crate) fn threads(&self) -> usize {
        self.threads
    }

    /// Passes run alone so far.
    pub(crate) fn solo_total(&self) -> u64 {
        self.solo_total
    }

    /// A state in which the next `passes` passes run alone (tests of the pool).
    #[cfg(test)]
    pub(crate) fn alone_for(passes: u32) -> Degrade {
        Degrade {
            left: passes,
            until: Instant::now() + Duration::from_secs(3600),
            span: passes,
            ..Degrade::new(2, 2)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ms(v: u64) -> Duration {
        Duration::from_millis(v)
    }

    #[test]
    fn a_pool_that_gets_its_cores_is_not_short_and_one_that_shares_them_is() {
        assert!(!short_of_cores(2.0, ms(198), ms(100)));
        assert!(
            short_of_cores(2.0, ms(100), ms(100)),
            "two threads on one core"
        );
        assert!(
            !short_of_cores(1.0, ms(10), ms(100)),
            "one thread never degrades"
        );
        // 4 threads on a 2-core machine are capped at 2: oversubscription is not contention.
        let d = Degrade::new(4, 2);
        assert_eq!(d.threads, 2);
    }

    #[test]
    fn two_short_windows_in_a_row_make_the_pool_run_alone_and_one_alone_does_not() {
        let (short, full) = ((ms(100), ms(100)), (ms(200), ms(100)));
        let (mut d, t0) = (Degrade::new(2, 2), Instant::now());
        d.decide_at(t0, short.0, short.1, 2.0);
        assert!(!d.solo_pass_at(t0), "one short window is only a suspicion");
        d.decide_at(t0, full.0, full.1, 2.0);
        d.decide_at(t0, short.0, short.1, 2.0);
        assert!(!d.solo_pass_at(t0), "a full window in between cleared it");
        d.decide_at(t0, short.0, short.1, 2.0);
        assert_eq!((0..10_000).filter(|_| d.solo_pass_at(t0)).count(), 64);
    }

    #[test]
    fn short_windows_make_the_solo_periods_double_and_a_full_window_ends_them() {
        let (mut d, t0) = (Degrade::new(2, 2), Instant::now());
        assert!(!d.solo_pass_at(t0));
        d.decide_at(t0, ms(100), ms(100), 2.0);
        d.decide_at(t0, ms(100), ms(100), 2.0);
        assert_eq!((0..10_000).filter(|_| d.solo_pass_at(t0)).count(), 64);
        d.decide_at(t0, ms(100), ms(100), 2.0);
        assert_eq!((0..10_000).filter(|_| d.solo_pass_at(t0)).count(), 128);
        d.decide_at(t0, ms(200), ms(100), 2.0);
        assert!(!d.solo_pass_at(t0));
        d.decide_at(t0, ms(100), ms(100), 2.0);
        d.decide_at(t0, ms(100), ms(100), 2.0);
        assert_eq!((0..10_000).filter(|_| d.solo_pass_at(t0)).count(), 64);
        assert_eq!(d.solo_total(), 256);
        for _ in 0..20 {
            d.decide_at(t0, ms(100), ms(100), 2.0);
        }
        assert_eq!(
            (0..10_000).filter(|_| d.solo_pass_at(t0)).count(),
            MAX_SOLO as usize
        );
    }

    #[test]
    fn forgetting_ends_a_period_alone_and_a_suspicion_and_keeps_the_count() {
        let (mut d, t0) = (Degrade::new(2, 2), Instant::now());
        d.decide_at(t0, ms(100), ms(100), 2.0);
        d.decide_at(t0, ms(100), ms(100), 2.0);
        assert!(d.solo_pass_at(t0));
        d.forget();
        assert!(!d.solo_pass_at(t0), "no longer alone");
        assert_eq!(d.solo_total(), 1);
        // A short window before forgetting no longer counts as the first of two.
        d.decide_at(t0, ms(100), ms(100), 2.0);
        d.forget();
        d.decide_at(t0, ms(100), ms(100), 2.0);
        assert!(!d.solo_pass_at(t0));
        assert_eq!(d.threads(), 2);
    }

    #[test]
    fn passes_alone_end_after_their_time_however_few_ran() {
        let (mut d, t0) = (Degrade::new(2, 2), Instant::now());
        d.decide_at(t0, ms(100), ms(100), 2.0);
        d.decide_at(t0, ms(100), ms(100), 2.0);
        assert_eq!(FIRST_SOLO_TIME, ms(20));
        // Long passes: three alone in the first 20 ms, then help is asked for again.
        for t in [1, 10, 19] {
            assert!(d.solo_pass_at(t0 + ms(t)), "alone at {t} ms");
        }
        assert!(!d.solo_pass_at(t0 + ms(20)));
        assert!(
            !d.solo_pass_at(t0 + ms(1)),
            "the period is over, not paused"
        );
        assert_eq!(d.solo_total(), 3);
        // Still short: the next period is twice as long, in passes and in time.
        let t1 = t0 + ms(30);
        d.decide_at(t1, ms(100), ms(100), 2.0);
        assert!(d.solo_pass_at(t1 + ms(39)));
        assert!(!d.solo_pass_at(t1 + ms(40)));
        d.decide_at(t1, ms(100), ms(100), 2.0);
        assert_eq!((0..10_000).filter(|_| d.solo_pass_at(t1)).count(), 256);
    }

    /// A pass of `len` starting at `t` (ms since `t0`), with the CPU clock reading `cpu`, in
    /// as many chunks as the pool has threads.
    fn pass(d: &mut Degrade, t0: Instant, t: f64, len: f64, cpu: f64) {
        let chunks = d.threads;
        pass_of(d, t0, t, len, cpu, chunks);
    }

    /// [`pass`] in `chunks` chunks.
    fn pass_of(d: &mut Degrade, t0: Instant, t: f64, len: f64, cpu: f64, chunks: usize) {
        let at = |ms: f64| t0 + Duration::from_secs_f64(ms / 1000.0);
        d.before_parallel_pass_at(at(t), || Some(Duration::from_secs_f64(cpu / 1000.0)));
        d.after_parallel_pass_at(at(t + len), Duration::from_secs_f64(len / 1000.0), chunks);
    }

    #[test]
    fn a_pass_keeps_busy_the_threads_its_chunks_fill_in_their_rounds() {
        assert_eq!(parallelism(12, 16), 8.0, "two rounds: 12 chunks, then 4");
        assert_eq!(parallelism(16, 16), 16.0);
        assert_eq!(parallelism(2, 1), 1.0);
        assert_eq!(parallelism(2, 3), 1.5);
        assert_eq!(parallelism(2, 50), 50.0 / 25.0);
        assert_eq!(parallelism(12, 256), 256.0 / 22.0);
        assert_eq!(parallelism(0, 0), 1.0, "no threads or chunks count as one");
    }

    /// 21 passes of 0.5 ms, one every 0.6 ms (two judged windows), in `chunks` chunks on
    /// `threads` threads whose CPU clock runs at `busy` threads per second of pass and at one
    /// between passes (the serial work); whether the pool then runs alone.
    fn runs_alone_after(threads: usize, chunks: usize, busy: f64) -> bool {
        let (mut d, t0) = (Degrade::new(threads, threads), Instant::now());
        let mut cpu = 0.0;
        for k in 0..=20 {
            let t = f64::from(k) * 0.6;
            pass_of(&mut d, t0, t, 0.5, cpu, chunks);
            cpu += 0.5 * busy + 0.1;
        }
        d.solo_pass_at(t0)
    }

    #[test]
    fn a_large_pool_runs_alone_only_when_it_gets_less_than_one_and_a_half_cores() {
        // 16 threads with work for all: 14 cores' worth (unequal chunks, a thread descheduled
        // now and then) is 14 times what one thread alone gets; 1.4 is not even 1.5.
        assert!(!runs_alone_after(16, 16, 14.0));
        assert!(!runs_alone_after(16, 64, 3.0));
        assert!(runs_alone_after(16, 64, 1.4));
        assert_eq!(
            ALONE_BELOW, 1.5,
            "on two threads, the shortfall's own threshold"
        );
        assert!(!short_of_cores(2.0, ms(151), ms(100)));
        assert!(short_of_cores(2.0, ms(149), ms(100)));
    }

    #[test]
    fn a_pass_is_judged_by_the_threads_its_chunks_keep_busy_not_by_the_pools_size() {
        // 16 chunks on 12 threads keep 8 busy: 8 threads' CPU is every core they could use.
        assert!(!runs_alone_after(12, 16, 8.0));
        // 3 chunks on 2 threads keep 1.5 busy: 1.2 cores' worth is not short of that (1.0 is
        // the threshold), though short of the two threads (1.5).
        assert!(!runs_alone_after(2, 3, 1.2));
        // One chunk has no help to give up, however little CPU its pass used; two do.
        assert!(!runs_alone_after(2, 1, 0.5));
        assert!(runs_alone_after(2, 2, 1.0));
        // The second window reads what the clock says (the first a little more: its first
        // pass is cold); below and above 1.5 on two.
        assert!(runs_alone_after(2, 2, 1.4));
        assert!(!runs_alone_after(2, 2, 1.6));
        assert!(
            !runs_alone_after(2, 3, 1.5),
            "3 chunks on 2 threads: 1.5 threads' work"
        );
        assert!(runs_alone_after(2, 3, 0.9));
    }

    #[test]
    fn a_window_closes_only_after_its_minimum_wall_time_and_time_in_passes() {
        // The CPU clock says nothing was used: a shortfall, once the window is long enough
        // (after a short window already, so that this one decides).
        let (mut d, t0) = (Degrade::new(2, 2), Instant::now());
        d.decide_at(t0, ms(100), ms(100), 2.0);
        pass(&mut d, t0, 0.0, 0.5, 0.0); // opens the window; wakes the workers (serial)
        pass(&mut d, t0, 0.55, 1.0, 0.0);
        pass(&mut d, t0, 1.6, 0.0, 0.0);
        assert!(!d.solo_pass_at(t0), "the window is still open");
        pass(&mut d, t0, 6.0, 0.5, 0.0); // long enough, but 1.5 ms in passes: cold, counts 0
        assert!(!d.solo_pass_at(t0), "too little time in passes yet");
        pass(&mut d, t0, 6.6, 0.5, 0.0); // warm: 1.5 ms
        assert!(!d.solo_pass_at(t0), "still too little");
        pass(&mut d, t0, 7.2, 0.5, 0.0); // 2 ms: judged at the next pass
        assert!(!d.solo_pass_at(t0));
        pass(&mut d, t0, 7.8, 0.0, 0.0);
        assert!(d.solo_pass_at(t0));
    }

    #[test]
    fn a_pass_that_wakes_sleeping_workers_is_not_taken_for_missing_cores() {
        // An 8 ms pass after a long serial stretch: the second thread joins after 5 ms, so
        // the 10 ms window used 10 + 3 ms of CPU. Counting the whole pass as a pass, 11 ms of
        // CPU over 8 ms is 1.4 threads: short. With its first 5 ms as serial work, 6 ms over
        // 3 ms is 2: not short.
        assert_eq!(WAKE_ALLOWANCE, ms(5));
        let (mut d, t0) = (Degrade::new(2, 2), Instant::now());
        pass(&mut d, t0, 0.0, 8.0, 0.0);
        pass(&mut d, t0, 10.0, 0.0, 13.0);
        assert!(!d.solo_pass_at(t0));
    }

    #[test]
    fn a_long_cold_pass_on_shared_cores_is_still_judged() {
        // Every pass cold (the session thread is descheduled between them) and each ran on
        // one thread: only the allowance is discounted, so the window closes and is short
        // (the second short window in a row).
        let (mut d, t0) = (Degrade::new(2, 2), Instant::now());
        d.decide_at(t0, ms(100), ms(100), 2.0);
        pass(&mut d, t0, 0.0, 8.0, 0.0);
        pass(&mut d, t0, 10.0, 0.0, 10.0);
        assert!(d.solo_pass_at(t0));
    }

    #[test]
    fn serial_work_between_passes_is_not_taken_for_missing_cores() {
        // 2 ms of passes on 2 threads (4 ms of CPU), the rest of the 6 ms window serial on one.
        let (mut d, t0) = (Degrade::new(2, 2), Instant::now());
        pass(&mut d, t0, 0.0, 0.0, 0.0);
        pass(&mut d, t0, 0.1, 2.0, 0.0);
        pass(&mut d, t0, 6.0, 0.0, 4.0 + 4.0);
        assert!(!d.solo_pass_at(t0));
    }
}
