//! The documented range of every numeric option, in one place: the command line checks them
//! at parse time, and `sweep --resume` checks a `meta.json` against the same rules.
//!
//! | option | range | why the bound |
//! |---|---|---|
//! | `--cores` | 1 ..= [`MAX_CORES`] (1024) | far above any one machine's hardware threads today; beyond it thread start-up alone would dominate, and the OS may refuse the threads |
//! | `--chunks` | 1 ..= [`MAX_CHUNKS`] | a pass makes min(K, N) chunks, so more than N never changes anything |
//! | `--n` | 1 ..= [`MAX_PARTICLES`], and within the machine's memory | see [`sph_solver::scene::memory`] for the per-particle estimate |
//! | `--steps` | 1 ..= [`MAX_STEPS`] | |
//! | `--resolution` (`wcsph`) | 4 ..= 400 ([`sph_solver::models::wcsph::params::RESOLUTIONS`]) | below 4 the column has no interior; 400 is 320 000 fluid particles |
//! | `--t-end` | 0 < t ≤ [`MAX_T_END_S`] s | far beyond the dam breaks (Martin & Moyce's data ends at 0.77 s; `wcsph`'s fluid splashes over the 2.5a walls after about 1.3 s, which ends the run with an error) |
//! | `--trials` | 1 ..= [`MAX_TRIALS`] | the grid's rounds |
//! | `--confirm-rounds` | 0 ..= [`MAX_TRIALS`] | |
//! | `--warmup` | 0 ..= [`MAX_WARMUP`] | |
//! | `--wait-quiet` | 0 ..= [`MAX_WAIT_QUIET_S`] s | an hour before each round is already a machine that will not calm down; the sweep then measures anyway and flags the cells |
//! | a sweep's cells | at most [`MAX_CELLS`] | the product of its lists |
//! | `--shard I/K` | 1 ≤ I ≤ K ≤ [`MAX_SHARDS`] (1024) | as many nodes as `--cores` allows threads; a shard also repeats its groups' `seq` cells, so far more shards than cells only wastes node time |

/// The most worker threads any command accepts.
pub const MAX_CORES: usize = 1024;
/// The most chunks per pass any command accepts.
pub const MAX_CHUNKS: usize = 10_000_000;
pub use sph_solver::MAX_PARTICLES;
/// The most steps of one run.
pub const MAX_STEPS: usize = 1_000_000_000;
/// The longest simulated time `--t-end` accepts, s.
pub const MAX_T_END_S: f64 = 100.0;
/// The most timed trials per cell of a sweep.
pub const MAX_TRIALS: usize = 1000;
/// The most untimed warm-up runs per cell (or group) of a sweep.
pub const MAX_WARMUP: usize = 1000;
/// The longest `sweep --wait-quiet` waits for a quiet machine before a round, s.
pub const MAX_WAIT_QUIET_S: usize = 3600;
/// The most cells one sweep may plan (the lists multiply: cores × chunks × N × …); far
/// beyond any study that finishes, and small enough that the plan itself fits in memory.
pub const MAX_CELLS: usize = 1_000_000;

/// The most parts `sweep --shard I/K` may split a plan into.
pub const MAX_SHARDS: usize = 1024;

/// A numeric option outside its documented range.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{what} must be between {min} and {max}, not {value}")]
pub struct OutOfRange {
    /// What the number counts, e.g. `cores`.
    pub what: &'static str,
    /// The value given.
    pub value: usize,
    /// The smallest allowed value.
    pub min: usize,
    /// The largest allowed value.
    pub max: usize,
}

/// `value` if it lies in `min..=max`.
pub fn check(
    what: &'static str,
    value: usize,
    min: usize,
    max: usize,
) -> Result<usize, OutOfRange> {
    if (min..=max).contains(&value) {
        Ok(value)
    } else {
        Err(OutOfRange {
            what,
            value,
            min,
            max,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_inside_the_range_pass_and_outside_are_named_with_the_range() {
        assert_eq!(check("cores", 1024, 1, MAX_CORES), Ok(1024));
        let err = check("cores", 1025, 1, MAX_CORES).unwrap_err();
        assert_eq!(
            err.to_string(),
            "cores must be between 1 and 1024, not 1025"
        );
        assert!(check("warm-ups", 0, 0, MAX_WARMUP).is_ok());
    }
}
