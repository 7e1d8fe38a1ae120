//! The thread pool that every rayon strategy owns.

use crate::{BuildError, Config};

/// A rayon pool with exactly `config.cores` threads, named `{name}-{index}`.
pub(crate) fn build(config: &Config, name: &'static str) -> Result<rayon::ThreadPool, BuildError> {
    rayon::ThreadPoolBuilder::new()
        .num_threads(config.cores)
        .thread_name(move |i| format!("{name}-{i}"))
        .build()
        .map_err(|e| BuildError::Pool(e.to_string()))
}
