//! `team`: an OpenMP-style team — `cores` threads kept for the whole run, each pass dealt
//! out in one contiguous share per thread, and a barrier between passes that spins, then
//! sleeps.
//!
//! **Scheduling.** [`Strategy::run`] starts exactly `cores` threads once per run and keeps
//! them; the session runs on the first (thread 0; the calling thread only waits for it).
//! Each pass is cut into `min(chunks, len)` balanced chunks, and thread `i` owns the `i`-th
//! contiguous share of them (`cores` shares as equal as whole chunks allow). A thread takes
//! its own share's chunks from the front; once its share is done, it takes chunks from the
//! back of the other shares (the next threads' first). With `--chunks` equal to `--cores`,
//! and every thread present, that is a static partition — the same block on the same thread
//! pass after pass, as `#pragma omp parallel for schedule(static)`. More chunks keep the
//! shares as static but let a thread that finished early take the last chunks of a slower
//! one (uneven work, a thread that is late), and a thread that is late — asleep, or
//! descheduled because another process wants its core — holds up the pass by at most the one
//! chunk it is in, not by its share: the pass ends once every chunk is done and every thread
//! that joined the pass has left.
//!
//! **Cost.** No thread start-up per pass. Per pass the session's thread opens the pass with
//! one atomic store and closes it with one read-modify-write; a worker joins with one
//! compare-and-swap and leaves with one subtraction (`TeamBoard`, in `erased_job`), and where
//! the session's thread spins while it waits (see below) each worker notes its CPU (a
//! `sched_getcpu` and a store to a line of its own, and one more store to clear it); each
//! chunk is taken with one compare-and-swap on its share's word (a cache line of its own, the
//! owner's unless others help) and moved out of its slot under an uncontended lock. The
//! thread that opens a pass does not reset the shares (each word carries its pass's tag; see
//! `Share`), so a share's line does not travel to it and back every pass. No queue, nothing
//! per element. Between passes a thread watches the pass word for up to 200 µs before it sleeps
//! on a condition variable, so back-to-back passes need no wake-up; the watching shows up as
//! CPU time.
//!
//! **A shared CPU.** A worker waiting for the next pass spins briefly, then yields its CPU
//! between checks: a pass does not wait for a worker that has not joined it, so a worker that
//! gives its CPU away (to a busy process, for a whole scheduling slice) costs the pass only its
//! help, and it gives it away between passes, not inside one. The session's thread, waiting
//! for the last workers of a pass, holds the pass up: with no more threads than CPUs it spins,
//! keeping its CPU, since giving it up costs a slice of milliseconds before it comes back; it
//! sleeps at once, though, when a worker inside the pass was last seen on its CPU, so as to
//! leave the CPU to it (each worker notes its CPU when it joins a pass: `whereabouts`). With
//! more threads than CPUs (`--cores` above the CPUs the threads may use), the team's threads
//! share CPUs among themselves, and it yields between checks too, for 20 µs (see
//! `spin_wait`).
//!
//! **Panics.** A kernel panic is caught per chunk; the first one is returned as
//! [`KernelPanic`] once the pass has finished, and the threads keep serving later passes.
//!
//! **Thread limits and shut-down.** As `crossbeam-pool`: a refused thread fails the run with
//! [`BuildError::ThreadStart`] before the session starts, and whenever the scope ends a
//! guard first tells the threads to exit, so the scope always joins them.

use std::cell::Cell;
use std::marker::PhantomData;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Mutex, PoisonError};

use crossbeam::utils::CachePadded;

use crate::erased_job::{ShutDownOnDrop, TeamBoard};
use crate::panic::FirstPanic;
use crate::spin_wait::Watch;
use crate::thread_start::ThreadStarts;
use crate::{
    BuildError, Config, Executor, Info, KernelPanic, Placement, Session, Split, Strategy,
    balanced_chunks,
};

/// `cores` threads kept for the run, one contiguous share of each pass's chunks per thread.
#[derive(Debug, Clone, Copy)]
pub struct Team {
    cores: usize,
    chunks: usize,
    placement: Placement,
    starts: ThreadStarts,
}

impl Strategy for Team {
    const INFO: Info = Info {
        name: "team",
        description: "an OpenMP-style team: --cores threads kept for the whole run (the \
                      steps run on one of them); each pass's min(--chunks, N) chunks dealt \
                      out as one contiguous share per thread, taken from the front by its \
                      owner and from the back by a thread done with its own; a spinning \
                      barrier between passes",
        calls: crate::Calls::Chunks,
    };

    fn build(config: &Config) -> Result<Self, BuildError> {
        config.validate()?;
        Ok(Team {
            cores: config.cores,
            chunks: config.chunks,
            placement: config.placement,
            starts: ThreadStarts::default(),
        })
    }

    /// Starts the threads, runs `session` on the first of them, then stops and joins the
    /// others.
    ///
    /// # Panics
    /// Re-raises a panic of `session` itself once the threads have been joined.
    fn run<S: Session>(&self, session: S) -> Result<S::Output, BuildError> {
        let board = TeamBoard::new(Watch::for_team(self.cores, self.placement));
        let executor = TeamExecutor {
            board: &board,
            threads: self.cores,
            chunks: self.chunks,
            shares: (0..self.cores).map(|_| Share::new()).collect(),
            passes: Cell::new(0),
            not_sync: PhantomData,
        };
        let (cores, placement, board) = (self.cores, self.placement, &board);
        std::thread::scope(|scope| {
            // Created before the first worker, so that every way out of this closure — a
            // return, a refused thread, a panicking session — releases the workers first.
            let _stop = ShutDownOnDrop(board);
            for i in 1..cores {
                self.starts.start(i, cores, || {
                    std::thread::Builder::new()
                        .name(format!("team-{i}"))
                        .spawn_scoped(scope, move || {
                            placement.on_start(i);
                            board.serve(i);
                        })
                })?;
            }
            let session_thread = self.starts.start(0, cores, || {
                std::thread::Builder::new()
                    .name("team-0".to_owned())
                    .spawn_scoped(scope, move || {
                        placement.on_start(0);
                        session.run(&executor)
                    })
            })?;
            let joined = session_thread.join();
            Ok(joined.unwrap_or_else(|payload| std::panic::resume_unwind(payload)))
        })
    }
}

/// Opens each pass on the board.
///
/// Deliberately not `Sync`: a kernel (which must be `Sync`) therefore cannot capture the
/// executor and start a nested pass from a worker, which the board refuses.
struct TeamExecutor<'a> {
    board: &'a TeamBoard,
    /// The team's threads, the session's included.
    threads: usize,
    chunks: usize,
    /// One per thread, kept from pass to pass.
    shares: Vec<Share>,
    /// The last pass's tag (see [`Share`]).
    passes: Cell<u64>,
    not_sync: PhantomData<Cell<()>>,
}

/// Bits of a share's word that tag it with its pass, and that hold each end of its range.
const TAG_BITS: u32 = 16;
const END_BITS: u32 = 24;
const END: u64 = (1 << END_BITS) - 1;
const TAGS: u64 = 1 << TAG_BITS;

/// The most chunks a pass is cut into: a share's ends are 24-bit fields of its word. Above
/// `--chunks`' range (10⁷), so from the command line a pass makes min(`--chunks`, N) chunks.
const MOST_CHUNKS: usize = END as usize;

/// The chunks a thread owns in a pass: a range of chunk indices, tagged with the pass. The
/// word holds the tag (the high 16 bits), `front` and `back` (exclusive; 24 bits each). The
/// owner takes chunks from the front, a thread whose own range is done takes them from the
/// back; each take is one compare-and-swap that moves one end, so every chunk is taken exactly
/// once.
///
/// The opener does not reset a share for a new pass: a word tagged with an earlier pass
/// stands for the pass's whole range, which every thread computes alike (`fresh`), and the
/// first take replaces it. So the opener never writes a share's cache line; the owner's first
/// take of a pass finds it in its own cache (shared at most with the threads that looked for
/// chunks to help with at the end of the last pass). A tag repeats after 2¹⁶ passes, so the
/// opener does reset every share when the tag comes round to 0 ([`Share::reset`]); no word is
/// then older than the last 2¹⁶ passes, and a word with the current tag was written in this
/// pass.
struct Share(CachePadded<AtomicU64>);

/// The pass a take is in: its tag, and the share's range in it before any take.
#[derive(Clone, Copy)]
struct InPass {
    tag: u64,
    fresh: (u64, u64),
}

impl Share {
    fn new() -> Share {
        Share(CachePadded::new(AtomicU64::new(0)))
    }

    /// Makes the share `fresh` with `tag`: only between passes, when nobody takes.
    fn reset(&self, pass: InPass) {
        let (front, back) = pass.fresh;
        self.0
            .store(Self::word(pass.tag, front, back), Ordering::Relaxed);
    }

    fn word(tag: u64, front: u64, back: u64) -> u64 {
        (tag << (2 * END_BITS)) | (front << END_BITS) | back
    }

    /// The next chunk from the front, for the owner.
    fn take_front(&self, pass: InPass) -> Option<usize> {
        self.take(pass, |front, back| (front + 1, back, front))
    }

    /// The last chunk not yet taken, for a helper.
    fn take_back(&self, pass: InPass) -> Option<usize> {
        self.take(pass, |front, back| (front, back - 1, back - 1))
    }

    /// Applies `step(front, back)` = (new front, new back, chunk taken) while any is left.
    fn take(&self, pass: InPass, step: impl Fn(u64, u64) -> (u64, u64, u64)) -> Option<usize> {
        let mut word = self.0.load(Ordering::Acquire);
        loop {
            let (front, back) = if word >> (2 * END_BITS) == pass.tag {
                ((word >> END_BITS) & END, word & END)
            } else {
                pass.fresh
            };
            if front >= back {
                return None;
            }
            let (front, back, taken) = step(front, back);
            match self.0.compare_exchange_weak(
                word,
                Self::word(pass.tag, front, back),
                Ordering::AcqRel,
                Ordering::Acquire,
            ) {
                Ok(_) => return usize::try_from(taken).ok(),
                Err(now) => word = now,
            }
        }
    }
}

impl Executor for TeamExecutor<'_> {
    fn for_each_chunk<O, F>(&self, out: O, kernel: F) -> Result<(), KernelPanic>
    where
        O: Split,
        F: Fn(usize, O) + Sync,
    {
        if out.is_empty() {
            return Ok(());
        }
        // Each chunk is moved out by the one thread whose compare-and-swap took its index.
        let chunks: Vec<Mutex<Option<(usize, O)>>> =
            balanced_chunks(out, self.chunks.min(MOST_CHUNKS))
                .into_iter()
                .map(|chunk| Mutex::new(Some(chunk)))
                .collect();
        let (n, threads) = (chunks.len() as u64, self.shares.len() as u64);
        let tag = (self.passes.get() + 1) % TAGS;
        self.passes.set(tag);
        let in_pass = |t: usize| InPass {
            tag,
            fresh: (t as u64 * n / threads, (t as u64 + 1) * n / threads),
        };
        let shares = &self.shares;
        if tag == 0 {
            // Before the pass opens (the board's opening store publishes it).
            for (t, share) in shares.iter().enumerate() {
                share.reset(in_pass(t));
            }
        }
        let panics = FirstPanic::default();
        let run = |i: usize| {
            let taken = chunks[i]
                .lock()
                .unwrap_or_else(PoisonError::into_inner)
                .take();
            if let Some((first, chunk)) = taken {
                panics.catch(|| kernel(first, chunk));
            }
        };

        // Run by thread `me`: its own share from the front, then the others' from the back,
        // the next threads' first. A panicking kernel is caught in `run`; the first panic is
        // kept.
        let job = |me: usize| {
            let mine = in_pass(me);
            while let Some(i) = shares[me].take_front(mine) {
                run(i);
            }
            let threads = shares.len();
            for other in (1..threads).map(|k| (me + k) % threads) {
                let theirs = in_pass(other);
                while let Some(i) = shares[other].take_back(theirs) {
                    run(i);
                }
            }
        };
        let escaped = self.board.run(&job);
        panics.or(escaped)
    }

    fn threads(&self) -> usize {
        self.threads
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spin_wait::Waiting;
    use crate::testing::{distinct, run_counting, thread_ids_per_pass};
    use std::iter;

    #[test]
    fn a_share_gives_every_chunk_once_to_its_owner_at_the_front_or_a_helper_at_the_back() {
        let share = Share::new();
        // Each pass's range stands in a word left by the pass before, which took it all (the
        // first in the new share's word).
        for (tag, fresh) in [(1, (10, 1010)), (2, (0, 500)), (3, (7, 8))] {
            let pass = InPass { tag, fresh };
            let (front, back) = std::thread::scope(|s| {
                let owner =
                    s.spawn(|| iter::from_fn(|| share.take_front(pass)).collect::<Vec<_>>());
                let helper =
                    s.spawn(|| iter::from_fn(|| share.take_back(pass)).collect::<Vec<_>>());
                (owner.join().unwrap(), helper.join().unwrap())
            });
            assert!(front.windows(2).all(|w| w[0] < w[1]), "the owner goes up");
            assert!(
                back.windows(2).all(|w| w[0] > w[1]),
                "the helper comes down"
            );
            let mut all = [front, back].concat();
            all.sort_unstable();
            let (from, to) = (fresh.0 as usize, fresh.1 as usize);
            assert_eq!(all, (from..to).collect::<Vec<_>>(), "pass {tag}");
            assert_eq!(
                (share.take_front(pass), share.take_back(pass)),
                (None, None)
            );
        }
    }

    #[test]
    fn a_share_at_the_largest_tag_and_ends_keeps_them_apart() {
        let share = Share::new();
        let pass = InPass {
            tag: TAGS - 1,
            fresh: (END - 3, END),
        };
        let word = |share: &Share| share.0.load(Ordering::Relaxed);
        assert_eq!(share.take_front(pass), Some(MOST_CHUNKS - 3));
        assert_eq!(word(&share), Share::word(TAGS - 1, END - 2, END));
        assert_eq!(share.take_back(pass), Some(MOST_CHUNKS - 1));
        assert_eq!(share.take_front(pass), Some(MOST_CHUNKS - 2));
        assert_eq!(
            (share.take_front(pass), share.take_back(pass)),
            (None, None)
        );
        assert_eq!(
            word(&share) >> (2 * END_BITS),
            TAGS - 1,
            "the tag is intact"
        );
    }

    #[test]
    fn every_pass_runs_every_chunk_while_the_tags_come_round() {
        // No worker serves the board, so the dispatcher takes every share's chunks, its own
        // from the front and the others' from the back, over passes of changing lengths. The
        // first pass has tag 0, which the new shares' words carry too: words as if left 2¹⁶
        // passes before, which only the reset tells from this pass's (without it, the first
        // pass would take no chunk).
        let board = TeamBoard::new(Watch::new(3, Waiting::Spin));
        let executor = TeamExecutor {
            board: &board,
            threads: 3,
            chunks: 5,
            shares: (0..3).map(|_| Share::new()).collect(),
            passes: Cell::new(TAGS - 1),
            not_sync: PhantomData,
        };
        let mut out = vec![0u64; 9];
        for pass in 1..=8u64 {
            let len = [9, 2, 7][pass as usize % 3];
            executor
                .for_each_chunk(&mut out[..len], |_, chunk: &mut [u64]| chunk.fill(pass))
                .unwrap();
            assert!(
                out[..len].iter().all(|&x| x == pass),
                "pass {pass}: {out:?}"
            );
        }
        assert_eq!(executor.passes.get(), 7);
    }

    #[test]
    fn with_every_thread_present_each_pass_gives_each_thread_one_block() {
        // One chunk a thread; each call sleeps 1 ms, far longer than a thread takes to join.
        let passes = thread_ids_per_pass::<Team>(3, 3, 30, 5);
        assert!(passes.iter().all(|pass| pass.len() == 3), "{passes:?}");
        let all: Vec<_> = passes.concat();
        assert!((2..=3).contains(&distinct(&all)), "{passes:?}");
        assert!(!all.contains(&std::thread::current().id()));
    }

    #[test]
    fn a_thread_the_system_refuses_fails_the_run_before_the_session_starts() {
        for (refuse, message) in [
            (2, "could not start worker thread 3 of 4"),
            (0, "could not start worker thread 1 of 4"),
        ] {
            let strategy = Team {
                cores: 4,
                chunks: 8,
                placement: Placement::OS,
                starts: ThreadStarts {
                    refuse: Some(refuse),
                },
            };
            let counted = run_counting(strategy, 100, 5);
            let err = counted.run.expect_err("the refused thread is an error");
            assert_eq!(err.to_string(), message);
            assert_eq!((counted.started, counted.ended), (0, 0), "{message}");
        }
    }
}
