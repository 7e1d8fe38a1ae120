//! `rayon-chunks`: `min(chunks, len)` balanced chunks, one rayon task per chunk (the
//! analogue of Haskell's `parListChunk`).
//!
//! **Scheduling.** Each pass cuts the output into `min(chunks, len)` balanced chunks and runs
//! them as a rayon parallel iterator over the chunk list inside the pool; rayon may group
//! neighbouring chunks onto one thread, but calls the kernel exactly once per chunk, and idle
//! threads steal the rest.
//!
//! **Cost.** No thread start-up (the pool of `cores` threads is built once, outside timing,
//! and the whole session runs on one of its threads, see `rayon_pool::run_inside`); per pass
//! a vector of chunks and about one `join` per chunk; nothing per element. Too few chunks
//! leave threads idle; too many add scheduling overhead.
//!
//! **Panics.** Rayon finishes both halves of a `join` and then re-raises a kernel's panic on
//! the thread that started the pass, where it is caught and returned as [`KernelPanic`].

use rayon::iter::{IntoParallelIterator, ParallelIterator};

use crate::{
    BuildError, Config, Executor, Info, KernelPanic, Session, Split, Strategy, balanced_chunks,
    panic,
};

/// Balanced chunks as a rayon parallel iterator over a pool of `cores` threads.
#[derive(Debug)]
pub struct RayonChunks {
    pool: rayon::ThreadPool,
    chunks: usize,
}

impl Strategy for RayonChunks {
    const INFO: Info = Info {
        name: "rayon-chunks",
        description: "min(--chunks, N) balanced chunks run as a rayon parallel iterator, one \
                      kernel call per chunk",
        calls: crate::Calls::Chunks,
    };

    fn build(config: &Config) -> Result<Self, BuildError> {
        config.validate()?;
        Ok(RayonChunks {
            pool: crate::rayon_pool::build(config, Self::INFO.name)?,
            chunks: config.chunks,
        })
    }

    fn run<S: Session>(&self, session: S) -> Result<S::Output, BuildError> {
        // The session runs on one of the pool's threads: see `rayon_pool::run_inside`.
        crate::rayon_pool::run_inside(
            &self.pool,
            session,
            RayonChunksExecutor {
                pool: &self.pool,
                chunks: self.chunks,
            },
        )
    }
}

struct RayonChunksExecutor<'a> {
    pool: &'a rayon::ThreadPool,
    chunks: usize,
}

impl Executor for RayonChunksExecutor<'_> {
    fn for_each_chunk<O, F>(&self, out: O, kernel: F) -> Result<(), KernelPanic>
    where
        O: Split,
        F: Fn(usize, O) + Sync,
    {
        if out.is_empty() {
            return Ok(());
        }
        let chunks = balanced_chunks(out, self.chunks);
        panic::catch(|| {
            self.pool.install(|| {
                chunks
                    .into_par_iter()
                    .for_each(|(first, chunk)| kernel(first, chunk));
            });
        })
    }

    fn threads(&self) -> usize {
        self.pool.current_num_threads()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn passes_are_spread_over_more_than_one_thread() {
        let passes = crate::testing::thread_ids_per_pass::<RayonChunks>(2, 16, 16, 1);
        assert!(crate::testing::distinct(&passes[0]) > 1, "{passes:?}");
    }
}
