//! `rayon-iter`: the naive data-parallel loop — rayon decides how to split the pass (the
//! analogue of Haskell's `parList`).
//!
//! **Scheduling.** The whole output is a `rayon::iter::split` parallel iterator whose splitter
//! halves it, down to single elements if rayon asks; rayon's adaptive splitting decides how
//! far to go (about a few pieces per thread, more where work is stolen), and the kernel is
//! called once per leaf that rayon does not split further. `--chunks` is ignored.
//!
//! **Cost.** No thread start-up (the pool of `cores` threads is built once, outside timing,
//! and the whole session runs on one of its threads, see `rayon_pool::run_inside`); per pass
//! one `join` and one split per halving. The number of kernel calls varies from run to run,
//! between 1 and `len`.
//!
//! **Panics.** Rayon finishes both halves of a `join` and then re-raises a kernel's panic on
//! the thread that started the pass, where it is caught and returned as [`KernelPanic`].

use rayon::iter::ParallelIterator;

use crate::{BuildError, Config, Executor, Info, KernelPanic, Session, Split, Strategy, panic};

/// Rayon's own splitting over a pool of `cores` threads.
#[derive(Debug)]
pub struct RayonIter {
    pool: rayon::ThreadPool,
}

impl Strategy for RayonIter {
    const INFO: Info = Info {
        name: "rayon-iter",
        description: "rayon parallel iterator over the elements; rayon decides the splitting \
                      (ignores --chunks)",
        calls: crate::Calls::Adaptive,
    };

    fn build(config: &Config) -> Result<Self, BuildError> {
        config.validate()?;
        Ok(RayonIter {
            pool: crate::rayon_pool::build(config, Self::INFO.name)?,
        })
    }

    fn run<S: Session>(&self, session: S) -> Result<S::Output, BuildError> {
        // The session runs on one of the pool's threads: see `rayon_pool::run_inside`.
        crate::rayon_pool::run_inside(&self.pool, session, RayonIterExecutor { pool: &self.pool })
    }
}

struct RayonIterExecutor<'a> {
    pool: &'a rayon::ThreadPool,
}

impl Executor for RayonIterExecutor<'_> {
    fn for_each_chunk<O, F>(&self, out: O, kernel: F) -> Result<(), KernelPanic>
    where
        O: Split,
        F: Fn(usize, O) + Sync,
    {
        if out.is_empty() {
            return Ok(());
        }
        panic::catch(|| {
            self.pool.install(|| {
                rayon::iter::split((0, out), halve).for_each(|(first, chunk)| kernel(first, chunk));
            });
        })
    }

    fn threads(&self) -> usize {
        self.pool.current_num_threads()
    }
}

/// Cuts `(first_index, out)` in two halves, unless it is a single element.
fn halve<O: Split>((first, out): (usize, O)) -> ((usize, O), Option<(usize, O)>) {
    let len = out.len();
    if len <= 1 {
        return ((first, out), None);
    }
    let mid = len / 2;
    let (left, right) = out.split_at(mid);
    ((first, left), Some((first + mid, right)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn halving_keeps_first_indices_and_stops_at_one_element() {
        let mut v = [0u8; 5];
        let ((f0, l), r) = halve((10, &mut v[..]));
        let (f1, r) = r.unwrap();
        assert_eq!((f0, l.len(), f1, r.len()), (10, 2, 12, 3));
        let mut one = [0u8; 1];
        assert!(halve((3, &mut one[..])).1.is_none());
    }

    #[test]
    fn kernels_run_only_on_the_pools_threads() {
        let passes = crate::testing::thread_ids_per_pass::<RayonIter>(2, 1, 64, 5);
        let all = passes.concat();
        assert!(crate::testing::distinct(&all) <= 2, "{passes:?}");
        assert!(!all.contains(&std::thread::current().id()));
    }
}
