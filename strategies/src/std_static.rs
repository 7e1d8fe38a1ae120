//! `std-static`: fresh threads every pass, one contiguous block each (static partitioning).
//!
//! **Scheduling.** Each pass opens a `std::thread::scope`, cuts the output into
//! `min(cores, len)` balanced blocks and starts one thread per block; the calling thread then
//! joins them all. No work moves between threads, so the slowest block sets the pass's time.
//! `--chunks` is ignored.
//!
//! **Cost.** Thread creation and join — `min(cores, len)` OS threads — on *every* pass, inside
//! the timed region; nothing per element.
//!
//! **Panics.** Every thread is joined; a panicked one becomes [`KernelPanic`] (the first, in
//! block order), and because every handle is joined the scope does not re-panic. If the
//! operating system refuses to start a thread, the pass panics (after joining the others).

use crate::{
    BuildError, Config, Executor, Info, KernelPanic, Session, Split, Strategy, balanced_chunks,
};

/// One fresh scoped thread per block, `cores` blocks per pass.
#[derive(Debug, Clone, Copy)]
pub struct StdStatic {
    cores: usize,
}

impl Strategy for StdStatic {
    const INFO: Info = Info {
        name: "std-static",
        description: "std scoped threads started every pass, one contiguous block of N/cores \
                      elements each (ignores --chunks)",
        uses_chunks: false,
    };

    fn build(config: &Config) -> Result<Self, BuildError> {
        config.validate()?;
        Ok(StdStatic {
            cores: config.cores,
        })
    }

    fn run<S: Session>(&self, session: S) -> S::Output {
        session.run(self)
    }
}

impl Executor for StdStatic {
    fn for_each_chunk<O, F>(&self, out: O, kernel: F) -> Result<(), KernelPanic>
    where
        O: Split,
        F: Fn(usize, O) + Sync,
    {
        if out.is_empty() {
            return Ok(());
        }
        let kernel = &kernel;
        std::thread::scope(|scope| {
            let threads: Vec<_> = balanced_chunks(out, self.cores)
                .into_iter()
                .map(|(first, block)| scope.spawn(move || kernel(first, block)))
                .collect();
            let mut result = Ok(());
            for thread in threads {
                if let Err(payload) = thread.join()
                    && result.is_ok()
                {
                    result = Err(KernelPanic::from_payload(payload));
                }
            }
            result
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing::{distinct, thread_ids_per_pass};

    #[test]
    fn passes_are_spread_over_more_than_one_thread() {
        let passes = thread_ids_per_pass::<StdStatic>(2, 1, 16, 1);
        assert!(distinct(&passes[0]) > 1, "{passes:?}");
    }

    #[test]
    fn every_pass_starts_its_own_threads() {
        let passes = thread_ids_per_pass::<StdStatic>(2, 1, 16, 3);
        assert_eq!(distinct(&passes.concat()), 6, "{passes:?}");
    }
}
