//! The one place in the workspace with `unsafe`: handing a job borrowed for one pass to
//! long-lived worker threads.
//!
//! Safe Rust cannot give a thread that outlives a borrow a reference to the borrowed data,
//! even when we know the thread stops using it before the borrow ends. Two boards do exactly
//! that and nothing else. Each publishes a `&(dyn Fn(usize) + Sync)` with its lifetime erased
//! ([`ErasedJob`]); every serving thread that joins the pass while it is open calls it once
//! (with its own index); the pass is closed to newcomers when the dispatcher's own call
//! returns; and the dispatcher's `run` returns only after every thread that joined has said it
//! is done with the job:
//! - [`JobBoard`] (`crossbeam-pool`) keeps its books under one mutex;
//! - [`TeamBoard`] (`team`) keeps them in one atomic word, with the job on its cache line
//!   (written only between passes, read only by a worker inside one), so that a pass costs the
//!   dispatcher one store and one read-modify-write on it (and two on a flag that only it
//!   touches) and each worker two, besides two stores by each worker to a slot of its own
//!   saying where it works (`spin_wait::Watch`), and takes a lock only to sleep, to wake a
//!   sleeper, or to keep a panic.
//!
//! The soundness argument lives entirely in this module, behind a safe API: no caller can make
//! a board call a job after `run` has returned, whatever the job does (a job that panics is
//! caught on the worker, which still signals completion and keeps serving) and whatever the
//! callers do (concurrent `run`s are serialised or refused; a shut-down board refuses new
//! jobs; any number of threads may serve, each one that joins is counted). The worst a misuse
//! can cause is a hang — e.g. a job that waits for a worker that never comes — never a
//! dangling reference.
//!
//! `scripts/miri.sh` runs this module's tests, and `team`'s, under Miri with 16 scheduling
//! seeds; it found no undefined behaviour on 6 December (nightly 2026-05-19).

#![allow(unsafe_code)]

mod board;
mod team;

pub(crate) use board::JobBoard;
pub(crate) use team::TeamBoard;

use std::mem;
use std::ptr::NonNull;

/// A `&(dyn Fn(usize) + Sync)` whose lifetime has been erased. Only the boards create and
/// call one, and only while the borrow it came from is alive (see their `run`).
#[derive(Clone, Copy)]
struct ErasedJob(NonNull<dyn Fn(usize) + Sync + 'static>);

// SAFETY: an `ErasedJob` is a shared reference to a `Sync` closure, and `&T` is `Send` when
// `T: Sync`. The lifetime it lost is upheld by the boards' protocols, not by the type.
unsafe impl Send for ErasedJob {}

impl ErasedJob {
    /// Erases the lifetime of `job`.
    fn new<'a>(job: &'a (dyn Fn(usize) + Sync + 'a)) -> Self {
        let ptr: NonNull<dyn Fn(usize) + Sync + 'a> = NonNull::from(job);
        // SAFETY: both types are the same fat pointer and differ only in the trait object's
        // lifetime bound, so the layout is identical. Creating the pointer is harmless; it is
        // dereferenced only in `call`, whose contract keeps it within `'a`.
        let ptr: NonNull<dyn Fn(usize) + Sync + 'static> = unsafe { mem::transmute(ptr) };
        ErasedJob(ptr)
    }

    /// Calls the job as thread `index`.
    ///
    /// # Safety
    /// The borrow that `self` was created from must still be alive.
    unsafe fn call(self, index: usize) {
        // SAFETY: the pointer came from a valid shared reference (`new`) and, by this
        // function's contract, that reference's borrow has not ended yet.
        let job = unsafe { self.0.as_ref() };
        job(index);
    }
}

/// A board whose serving threads can be told to exit.
pub(crate) trait ShutDown {
    /// Makes every serving thread return once it has finished any job in flight.
    fn shut_down(&self);
}

impl ShutDown for JobBoard {
    fn shut_down(&self) {
        JobBoard::shut_down(self);
    }
}

impl ShutDown for TeamBoard {
    fn shut_down(&self) {
        TeamBoard::shut_down(self);
    }
}

/// Tells a board's serving threads to exit when dropped, including during unwinding: a
/// strategy creates it before its first worker, so that every way out of its thread scope —
/// a return, a refused thread, a panicking session — releases the workers and the scope can
/// join them.
pub(crate) struct ShutDownOnDrop<'a, B: ShutDown>(pub(crate) &'a B);

impl<B: ShutDown> Drop for ShutDownOnDrop<'_, B> {
    fn drop(&mut self) {
        self.0.shut_down();
    }
}

/// Yields until `done()`, for the boards' tests; the test's watchdog is the test harness's own.
#[cfg(test)]
fn wait_for(done: impl Fn() -> bool) {
    while !done() {
        std::thread::yield_now();
    }
}

/// Serves a board made by `new` on `workers` scoped threads (indices 1 and up, each calling
/// `serve`) while `f` runs, then shuts it down; once for each way of waiting. For the boards'
/// tests.
#[cfg(test)]
fn served<B: ShutDown + Sync>(
    workers: usize,
    new: impl Fn(crate::spin_wait::Watch) -> B,
    serve: impl Fn(&B, usize) + Sync,
    f: impl Fn(&B) + Sync,
) {
    use crate::spin_wait::{Waiting, Watch};
    for waiting in [Waiting::Spin, Waiting::Yield] {
        let board = new(Watch::new(workers + 1, waiting));
        std::thread::scope(|s| {
            for index in 1..=workers {
                let (board, serve) = (&board, &serve);
                s.spawn(move || serve(board, index));
            }
            let _stop = ShutDownOnDrop(&board);
            f(&board);
        });
    }
}

/// Aborts the process when dropped. Armed around the calls of a job and disarmed with
/// `mem::forget` after them, so only an unwind that escaped `panic::catch` reaches it: going
/// on would skip the bookkeeping that keeps an erased job from outliving its borrow.
struct AbortOnUnwind;

impl Drop for AbortOnUnwind {
    fn drop(&mut self) {
        std::process::abort();
    }
}
