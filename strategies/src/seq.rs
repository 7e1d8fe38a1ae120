//! `seq`: the sequential baseline — the whole pass is one kernel call on the calling thread.

use crate::{BuildError, Config, Executor, Info, KernelPanic, Session, Split, Strategy, panic};

/// The sequential baseline. Ignores `cores` and `chunks`.
#[derive(Debug, Clone, Copy, Default)]
pub struct Seq;

impl Strategy for Seq {
    const INFO: Info = Info {
        name: "seq",
        description: "sequential baseline: each pass is one chunk on the calling thread \
                      (ignores --cores and --chunks)",
        calls: crate::Calls::Whole,
    };

    fn build(config: &Config) -> Result<Self, BuildError> {
        config.validate()?;
        Ok(Seq)
    }

    fn run<S: Session>(&self, session: S) -> Result<S::Output, BuildError> {
        Ok(session.run(&SeqExecutor))
    }
}

/// Runs every pass as a single chunk, in place.
pub struct SeqExecutor;

impl Executor for SeqExecutor {
    fn for_each_chunk<O, F>(&self, out: O, kernel: F) -> Result<(), KernelPanic>
    where
        O: Split,
        F: Fn(usize, O) + Sync,
    {
        if out.is_empty() {
            return Ok(());
        }
        panic::catch(|| kernel(0, out))
    }

    fn threads(&self) -> usize {
        1
    }
}
