//! 95 % confidence intervals by the percentile bootstrap: pure functions of the trial times
//! and a seeded generator, so a results directory is reproduced exactly.
//!
//! - **Mean**: draw the cell's k trial times k times with replacement, take the mean; repeat
//!   [`RESAMPLES`] times; the interval runs from the 2.5th to the 97.5th percentile of those
//!   means (nearest rank: the values at positions ⌊0.025·B⌋ and ⌈0.975·B⌉ − 1 of the sorted B
//!   resampled means, 0-based).
//! - **Speedup** (a ratio of means): the `seq` reference's trials and the cell's trials are
//!   resampled independently, and each draw gives mean(seq*) / mean(cell*).
//!
//! [`RESAMPLES`] = 10 000 puts the Monte Carlo error of each percentile well below the
//! intervals' own width. With the few trials a sweep takes (5 by default) the percentile
//! bootstrap is known to be **too narrow** (its coverage falls short of 95 % for small k):
//! read an interval as the least uncertainty there is, never as a guarantee. One trial gives
//! no interval.
//!
//! The generator is [`SplitMix64`], seeded per cell from the sweep's `--seed` and the cell's
//! key, so every cell has its own stream and resuming a sweep gives the same intervals.

use crate::checksum::fingerprint;
use crate::scene::splitmix::SplitMix64;

pub use crate::results::stats::{CONFIDENCE, Interval, RESAMPLES};

/// The generator of one cell: `seed` mixed with the cell's key text, plus a `stream` number
/// for the cell's separate intervals.
pub fn rng_for(seed: u64, key: &str, stream: u64) -> SplitMix64 {
    SplitMix64::new(seed ^ fingerprint(key.as_bytes()) ^ stream.wrapping_mul(0x9e37_79b9_7f4a_7c15))
}

/// The percentile-bootstrap interval of the mean of `xs` (`None` for fewer than 2 values).
pub fn mean_interval(xs: &[f64], resamples: usize, rng: &mut SplitMix64) -> Option<Interval> {
    if xs.len() < 2 || resamples == 0 {
        return None;
    }
    let mut means: Vec<f64> = (0..resamples).map(|_| resampled_mean(xs, rng)).collect();
    Some(percentiles(&mut means))
}

/// The percentile-bootstrap interval of mean(`num`) / mean(`den`), the two resampled
/// independently (`None` unless both have at least 2 values).
pub fn ratio_interval(
    num: &[f64],
    den: &[f64],
    resamples: usize,
    rng: &mut SplitMix64,
) -> Option<Interval> {
    if num.len() < 2 || den.len() < 2 || resamples == 0 {
        return None;
    }
    let mut ratios: Vec<f64> = (0..resamples)
        .map(|_| resampled_mean(num, rng) / resampled_mean(den, rng))
        .collect();
    Some(percentiles(&mut ratios))
}

/// The mean of `xs.len()` draws from `xs` with replacement.
fn resampled_mean(xs: &[f64], rng: &mut SplitMix64) -> f64 {
    let k = xs.len();
    let sum: f64 = (0..k).map(|_| xs[below(rng, k)]).sum();
    sum / k as f64
}

/// A uniform index in `0..k` (Lemire's multiply-shift; its bias is below 2⁻⁵⁰ for the trial
/// counts a sweep allows).
fn below(rng: &mut SplitMix64, k: usize) -> usize {
    ((u128::from(rng.next_u64()) * k as u128) >> 64) as usize
}

/// The 2.5th and 97.5th percentiles (nearest rank) of `values`.
fn percentiles(values: &mut [f64]) -> Interval {
    values.sort_by(f64::total_cmp);
    let b = values.len();
    let tail = (1.0 - CONFIDENCE) / 2.0;
    let low = ((tail * b as f64).floor() as usize).min(b - 1);
    let high = (((1.0 - tail) * b as f64).ceil() as usize).clamp(1, b) - 1;
    Interval {
        low: values[low],
        high: values[high],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_mean_interval_of_known_data_matches_the_normal_approximation() {
        // 1..=10: mean 5.5, population sd 2.872, so resampled means have sd 2.872/√10 = 0.908
        // and a 95 % interval of about 5.5 ± 1.96 · 0.908 = [3.72, 7.28].
        let xs: Vec<f64> = (1..=10).map(f64::from).collect();
        let ci = mean_interval(&xs, RESAMPLES, &mut SplitMix64::new(7)).unwrap();
        assert!((ci.low - 3.72).abs() < 0.15, "{ci:?}");
        assert!((ci.high - 7.28).abs() < 0.15, "{ci:?}");
        assert!(ci.contains(5.5));
    }

    #[test]
    fn the_same_seed_gives_the_same_interval_and_another_seed_another() {
        // Enough distinct values that the interval's ends depend on the draws.
        let xs: Vec<f64> = (0..40)
            .map(|i| 0.3 + f64::from(i * 7 % 40) * 0.001)
            .collect();
        let a = mean_interval(&xs, RESAMPLES, &mut rng_for(2019, "cell", 0));
        let b = mean_interval(&xs, RESAMPLES, &mut rng_for(2019, "cell", 0));
        let c = mean_interval(&xs, RESAMPLES, &mut rng_for(2019, "other cell", 0));
        assert_eq!(a, b);
        assert_ne!(a, c);
    }

    #[test]
    fn constant_trials_give_a_point_interval_and_one_trial_none() {
        let ci = mean_interval(&[2.0, 2.0, 2.0], 100, &mut SplitMix64::new(1)).unwrap();
        assert_eq!((ci.low, ci.high), (2.0, 2.0));
        assert_eq!(mean_interval(&[2.0], 100, &mut SplitMix64::new(1)), None);
        assert_eq!(
            ratio_interval(&[1.0, 1.0], &[2.0], 100, &mut SplitMix64::new(1)),
            None
        );
    }

    #[test]
    fn the_speedup_interval_brackets_the_ratio_of_means() {
        let seq = [1.00, 1.02, 0.98, 1.01, 0.99];
        let cell = [0.50, 0.52, 0.49, 0.51, 0.48];
        let ci = ratio_interval(&seq, &cell, RESAMPLES, &mut SplitMix64::new(3)).unwrap();
        let ratio = 1.0 / 0.5;
        assert!(ci.low < ratio && ratio < ci.high, "{ci:?}");
        // Every resampled ratio lies between the extreme ratios of the data.
        assert!(ci.low >= 0.98 / 0.52 && ci.high <= 1.02 / 0.48, "{ci:?}");
    }

    #[test]
    fn percentiles_are_the_nearest_ranks_at_two_and_a_half_and_ninety_seven_and_a_half() {
        let mut v: Vec<f64> = (0..1000).rev().map(f64::from).collect();
        let i = percentiles(&mut v);
        assert_eq!((i.low, i.high), (25.0, 974.0));
    }

    #[test]
    fn intervals_overlap_when_they_share_a_point() {
        let a = Interval {
            low: 1.0,
            high: 2.0,
        };
        assert!(a.overlaps(&Interval {
            low: 2.0,
            high: 3.0
        }));
        assert!(!a.overlaps(&Interval {
            low: 2.1,
            high: 3.0
        }));
    }
}
