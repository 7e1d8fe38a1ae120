//! `rayon-spawn`: one rayon task per element, to show what per-element scheduling costs.
//!
//! **Scheduling.** Each pass cuts the output into single-element chunks and, inside
//! `pool.scope`, spawns one task per element; idle threads steal tasks from the spawning
//! thread's deque. The scope ends when every task has run. `--chunks` is ignored.
//!
//! **Cost.** No thread start-up (the pool of `cores` threads is built once, outside timing,
//! and the whole session runs on one of its threads, see `rayon_pool::run_inside`), but per
//! element: one boxed task (a heap allocation), one deque push and pop (or steal) and
//! one kernel call; plus a `len`-long vector of chunks per pass. This overhead is the point of
//! the strategy.
//!
//! **Panics.** Rayon's scope waits for every task, then re-raises the first kernel panic on
//! the thread that started the pass, where it is caught and returned as [`KernelPanic`].

use crate::{
    BuildError, Config, Executor, Info, KernelPanic, Session, Split, Strategy, balanced_chunks,
    panic,
};

/// One rayon task per element on a pool of `cores` threads.
#[derive(Debug)]
pub struct RayonSpawn {
    pool: rayon::ThreadPool,
}

impl Strategy for RayonSpawn {
    const INFO: Info = Info {
        name: "rayon-spawn",
        description: "one rayon task spawned per element in a scope (ignores --chunks)",
        calls: crate::Calls::Elements,
    };

    fn build(config: &Config) -> Result<Self, BuildError> {
        config.validate()?;
        Ok(RayonSpawn {
            pool: crate::rayon_pool::build(config, Self::INFO.name)?,
        })
    }

    fn run<S: Session>(&self, session: S) -> Result<S::Output, BuildError> {
        // The session runs on one of the pool's threads: see `rayon_pool::run_inside`.
        crate::rayon_pool::run_inside(&self.pool, session, RayonSpawnExecutor { pool: &self.pool })
    }
}

struct RayonSpawnExecutor<'a> {
    pool: &'a rayon::ThreadPool,
}

impl Executor for RayonSpawnExecutor<'_> {
    fn for_each_chunk<O, F>(&self, out: O, kernel: F) -> Result<(), KernelPanic>
    where
        O: Split,
        F: Fn(usize, O) + Sync,
    {
        if out.is_empty() {
            return Ok(());
        }
        let len = out.len();
        let elements = balanced_chunks(out, len);
        let kernel = &kernel;
        panic::catch(|| {
            self.pool.scope(|scope| {
                for (first, element) in elements {
                    scope.spawn(move |_| kernel(first, element));
                }
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
        let passes = crate::testing::thread_ids_per_pass::<RayonSpawn>(2, 1, 64, 1);
        assert!(crate::testing::distinct(&passes[0]) > 1, "{passes:?}");
    }
}
