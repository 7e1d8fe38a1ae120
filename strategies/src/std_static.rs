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
//! block order), and because every handle is joined the scope does not re-panic.
//!
//! **Thread limits.** If the operating system refuses to start a block's thread, the blocks
//! already started are joined, the pass returns an error (so the session stops) and the run
//! fails with [`BuildError::ThreadStart`] instead of returning the session's output.

use std::cell::RefCell;

use crate::thread_start::ThreadStarts;
use crate::{
    BuildError, Config, Executor, Info, KernelPanic, Placement, Session, Split, Strategy,
    balanced_chunks,
};

/// One fresh scoped thread per block, `cores` blocks per pass.
#[derive(Debug, Clone, Copy)]
pub struct StdStatic {
    cores: usize,
    placement: Placement,
    starts: ThreadStarts,
}

impl Strategy for StdStatic {
    const INFO: Info = Info {
        name: "std-static",
        description: "std scoped threads started every pass, one contiguous block of N/cores \
                      elements each (ignores --chunks)",
        calls: crate::Calls::Blocks,
    };

    fn build(config: &Config) -> Result<Self, BuildError> {
        config.validate()?;
        Ok(StdStatic {
            cores: config.cores,
            placement: config.placement,
            starts: ThreadStarts::default(),
        })
    }

    fn run<S: Session>(&self, session: S) -> Result<S::Output, BuildError> {
        let exec = StdStaticExecutor {
            strategy: *self,
            refused: RefCell::new(None),
        };
        let output = session.run(&exec);
        match exec.refused.into_inner() {
            Some(refused) => Err(refused),
            None => Ok(output),
        }
    }
}

/// Starts the threads of each pass and remembers the first thread the system refused.
struct StdStaticExecutor {
    strategy: StdStatic,
    refused: RefCell<Option<BuildError>>,
}

impl Executor for StdStaticExecutor {
    fn for_each_chunk<O, F>(&self, out: O, kernel: F) -> Result<(), KernelPanic>
    where
        O: Split,
        F: Fn(usize, O) + Sync,
    {
        if out.is_empty() {
            return Ok(());
        }
        let kernel = &kernel;
        let blocks = balanced_chunks(out, self.strategy.cores);
        let count = blocks.len();
        std::thread::scope(|scope| {
            let mut threads = Vec::with_capacity(count);
            let mut refused = None;
            for (index, (first, block)) in blocks.into_iter().enumerate() {
                let started = self.strategy.starts.start(index, count, || {
                    let placement = self.strategy.placement;
                    std::thread::Builder::new().spawn_scoped(scope, move || {
                        placement.on_start(index);
                        kernel(first, block)
                    })
                });
                match started {
                    Ok(thread) => threads.push(thread),
                    Err(e) => {
                        refused = Some(e);
                        break;
                    }
                }
            }
            let mut result = Ok(());
            for thread in threads {
                if let Err(payload) = thread.join()
                    && result.is_ok()
                {
                    result = Err(KernelPanic::from_payload(payload));
                }
            }
            if let Some(e) = refused {
                // The pass's error only stops the session; `run` reports the refusal itself.
                let message = e.to_string();
                self.refused.borrow_mut().get_or_insert(e);
                return Err(KernelPanic { message });
            }
            result
        })
    }

    fn threads(&self) -> usize {
        self.strategy.cores
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing::{distinct, run_counting, thread_ids_per_pass};

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

    #[test]
    fn a_block_thread_the_system_refuses_fails_the_run_after_joining_the_blocks_started() {
        let strategy = StdStatic {
            cores: 4,
            placement: Placement::OS,
            starts: ThreadStarts { refuse: Some(2) },
        };
        let counted = run_counting(strategy, 100, 5);
        let err = counted.run.expect_err("the refused thread is an error");
        assert_eq!(err.to_string(), "could not start worker thread 3 of 4");
        assert!(matches!(
            err,
            BuildError::ThreadStart {
                thread: 3,
                threads: 4,
                ..
            }
        ));
        // Blocks 1 and 2 ran to the end before `run` returned; the session stopped there.
        assert_eq!((counted.started, counted.ended), (2, 2));
    }
}
