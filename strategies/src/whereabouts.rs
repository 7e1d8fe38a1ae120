//! Which CPU each worker of a team runs on while it is inside a pass, so that the session's
//! thread, waiting for the last workers of a pass, can tell whether one of them shares its CPU
//! (the boards of `team` and `crossbeam-pool`, in `erased_job`).
//!
//! That thread holds up the pass, and it has two ways to wait, each right in one case only.
//! Spinning keeps its CPU until the operating system takes it away, which is what it wants
//! when the workers it waits for run elsewhere: giving the CPU up (a yield, a sleep) hands it
//! to whatever else is runnable there, and a busy process, once it has the CPU, keeps it for a
//! whole scheduling slice (milliseconds; on Linux's EEVDF scheduler a yield also gives it to
//! no other thread that has had more than its share lately, so a yielding waiter often just
//! spins on). Sleeping at once is right when a worker it waits for is queued behind it on the
//! same CPU: spinning there only delays it. So each worker writes its CPU into its slot when it
//! joins a pass and clears it when it leaves, and the waiting thread, finding a worker on its
//! own CPU, sleeps.
//!
//! A slot is a hint: a thread moved by the operating system since it wrote it is found where
//! it was. Where the CPU cannot be asked (not Linux, or under Miri), no thread is ever found
//! beside another, so the session's thread of `team` and `crossbeam-pool` watches by yielding
//! there instead (`spin_wait::Waiting`).

use std::sync::atomic::{AtomicUsize, Ordering};

use crossbeam::utils::CachePadded;

/// A slot's value while its thread waits.
const AWAY: usize = usize::MAX;

/// One slot per thread of a team (0 is the session's thread, which the boards never note: only
/// it looks).
pub(crate) struct Whereabouts {
    /// The CPU (as `sched_getcpu` numbers it) each thread last said it works on, or [`AWAY`].
    slots: Box<[CachePadded<AtomicUsize>]>,
}

impl Whereabouts {
    /// Whether this system can say which CPU a thread runs on.
    pub(crate) fn available() -> bool {
        cfg!(all(target_os = "linux", not(miri)))
    }

    /// `threads` slots, all away.
    pub(crate) fn new(threads: usize) -> Self {
        Whereabouts {
            slots: (0..threads)
                .map(|_| CachePadded::new(AtomicUsize::new(AWAY)))
                .collect(),
        }
    }

    /// Thread `me` is at work, on the CPU it runs on now. An index without a slot is ignored
    /// (a board may be served by more threads than it was made for; they are never found).
    pub(crate) fn busy(&self, me: usize) {
        if let Some(slot) = self.slots.get(me) {
            slot.store(current_cpu().unwrap_or(AWAY), Ordering::Relaxed);
        }
    }

    /// Thread `me` waits.
    pub(crate) fn away(&self, me: usize) {
        if let Some(slot) = self.slots.get(me) {
            slot.store(AWAY, Ordering::Relaxed);
        }
    }

    /// Whether another busy thread last said it runs on the CPU that `me` runs on now.
    pub(crate) fn beside_busy(&self, me: usize) -> bool {
        let Some(cpu) = current_cpu() else {
            return false;
        };
        self.slots
            .iter()
            .enumerate()
            .any(|(i, slot)| i != me && slot.load(Ordering::Relaxed) == cpu)
    }
}

/// The CPU the calling thread runs on, where it can be asked.
fn current_cpu() -> Option<usize> {
    #[cfg(all(target_os = "linux", not(miri)))]
    {
        nix::sched::sched_getcpu().ok()
    }
    #[cfg(not(all(target_os = "linux", not(miri))))]
    {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_waiter_finds_a_busy_thread_on_its_cpu_and_never_itself_or_one_away() {
        let cpus = Whereabouts::new(3);
        assert!(!cpus.beside_busy(0), "everyone away");
        cpus.busy(0);
        assert!(!cpus.beside_busy(0), "only itself");
        // Slot 1 says thread 1 runs where the caller runs (it is the caller, pretending).
        cpus.busy(1);
        if Whereabouts::available() {
            // The calling thread may have moved between the two calls: retry.
            assert!((0..100).any(|_| {
                cpus.busy(1);
                cpus.beside_busy(0)
            }));
        } else {
            assert!(!cpus.beside_busy(0), "no CPU to ask: never beside");
        }
        if Whereabouts::available() {
            assert!(
                (0..100).any(|_| {
                    cpus.busy(1);
                    cpus.beside_busy(7)
                }),
                "a waiter without a slot finds thread 1 all the same"
            );
        }
        cpus.away(1);
        assert!(!cpus.beside_busy(0), "thread 1 waits now");
        cpus.away(0);
        cpus.busy(7);
        assert!(
            !cpus.beside_busy(1),
            "a thread without a slot is never found"
        );
    }
}
