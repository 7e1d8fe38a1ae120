//! The thread pool that every rayon strategy owns.

use crate::{BuildError, Config, Executor, Session};

/// A rayon pool with exactly `config.cores` threads, named `{name}-{index}`, each placed by
/// `config.placement` as it starts.
pub(crate) fn build(config: &Config, name: &'static str) -> Result<rayon::ThreadPool, BuildError> {
    let placement = config.placement;
    rayon::ThreadPoolBuilder::new()
        .num_threads(config.cores)
        .thread_name(move |i| format!("{name}-{i}"))
        .start_handler(move |i| placement.on_start(i))
        .build()
        .map_err(|e| BuildError::Pool(e.to_string()))
}

/// Runs `session` on one of `pool`'s threads, with `exec`.
///
/// The step loop's serial parts then run on a worker, which also takes part in every pass:
/// the pool's `cores` threads do all the work (the caller only waits for the result), and a
/// pass starts and ends without handing work to, and waking, a thread outside the pool.
/// Never fails: the pool's threads were started in [`build`].
pub(crate) fn run_inside<S, E>(
    pool: &rayon::ThreadPool,
    session: S,
    exec: E,
) -> Result<S::Output, BuildError>
where
    S: Session,
    E: Executor + Sync,
{
    Ok(pool.install(|| session.run(&exec)))
}
