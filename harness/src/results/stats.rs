//! The statistics of a cell's trials: pure functions of the trial times, in seconds.
//!
//! - mean: the sum in trial order divided by the count;
//! - stddev: the **sample** standard deviation, √(Σ(t − mean)² / (k − 1)); undefined (`None`)
//!   for a single trial;
//! - median: the middle value, or the mean of the two middle values for an even count;
//! - MAD: the median absolute deviation, median(|t − median|), unscaled;
//! - outliers: trials with |t − median| > 3 · MAD ([`OUTLIER_MADS`]). When more than half the
//!   trials are equal the MAD is 0, and every trial that differs from the median counts.
//!
//! The summary's intervals are [`Interval`]s at [`CONFIDENCE`], computed by
//! [`crate::results::intervals`].

/// The intervals' confidence level.
pub const CONFIDENCE: f64 = 0.95;

/// A confidence interval.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Interval {
    /// Lower end.
    pub low: f64,
    /// Upper end.
    pub high: f64,
}

impl Interval {
    /// Whether the two intervals share a point.
    pub fn overlaps(&self, other: &Interval) -> bool {
        self.low <= other.high && other.low <= self.high
    }

    /// Whether `x` lies inside.
    pub fn contains(&self, x: f64) -> bool {
        self.low <= x && x <= self.high
    }
}

/// How many MADs from the median make a trial an outlier.
pub const OUTLIER_MADS: f64 = 3.0;

/// The statistics of one set of trial times.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Stats {
    /// Arithmetic mean, s.
    pub mean: f64,
    /// Sample standard deviation, s (`None` for one trial).
    pub stddev: Option<f64>,
    /// Fastest trial, s.
    pub min: f64,
    /// Median, s.
    pub median: f64,
    /// Slowest trial, s.
    pub max: f64,
    /// Number of outliers by the |t − median| > 3 · MAD rule.
    pub outliers: usize,
}

impl Stats {
    /// The statistics of `times` (seconds); `None` when there are none.
    pub fn of(times: &[f64]) -> Option<Stats> {
        if times.is_empty() {
            return None;
        }
        Some(Stats {
            mean: mean(times),
            stddev: sample_stddev(times),
            min: times.iter().copied().fold(f64::INFINITY, f64::min),
            median: median(times),
            max: times.iter().copied().fold(f64::NEG_INFINITY, f64::max),
            outliers: outliers(times),
        })
    }
}

/// The mean: the sum in the given order divided by the count (NaN when empty).
pub fn mean(xs: &[f64]) -> f64 {
    xs.iter().sum::<f64>() / xs.len() as f64
}

/// The sample standard deviation (divisor k − 1); `None` for fewer than two values.
pub fn sample_stddev(xs: &[f64]) -> Option<f64> {
    if xs.len() < 2 {
        return None;
    }
    let m = mean(xs);
    let squares: f64 = xs.iter().map(|x| (x - m) * (x - m)).sum();
    Some((squares / (xs.len() - 1) as f64).sqrt())
}

/// The median; the mean of the two middle values for an even count (NaN when empty).
pub fn median(xs: &[f64]) -> f64 {
    if xs.is_empty() {
        return f64::NAN;
    }
    let mut sorted = xs.to_vec();
    sorted.sort_by(f64::total_cmp);
    let mid = sorted.len() / 2;
    if sorted.len() % 2 == 1 {
        sorted[mid]
    } else {
        (sorted[mid - 1] + sorted[mid]) / 2.0
    }
}

/// The median absolute deviation from the median (unscaled).
pub fn mad(xs: &[f64]) -> f64 {
    let m = median(xs);
    let deviations: Vec<f64> = xs.iter().map(|x| (x - m).abs()).collect();
    median(&deviations)
}

/// How many values lie more than [`OUTLIER_MADS`] MADs from the median.
pub fn outliers(xs: &[f64]) -> usize {
    let (m, mad) = (median(xs), mad(xs));
    xs.iter()
        .filter(|x| (*x - m).abs() > OUTLIER_MADS * mad)
        .count()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mean_and_sample_stddev_match_hand_computation() {
        assert_eq!(mean(&[1.0, 2.0, 3.0]), 2.0);
        assert_eq!(sample_stddev(&[1.0, 2.0, 3.0]), Some(1.0));
        // Σ(t − 2.5)² = 5, divided by k − 1 = 3.
        assert_eq!(
            sample_stddev(&[1.0, 2.0, 3.0, 4.0]),
            Some((5.0f64 / 3.0).sqrt())
        );
        assert_eq!(sample_stddev(&[2.0, 4.0]), Some(2.0f64.sqrt()));
    }

    #[test]
    fn one_trial_has_no_stddev() {
        assert_eq!(sample_stddev(&[1.5]), None);
        let s = Stats::of(&[1.5]).unwrap();
        assert_eq!(
            (s.mean, s.min, s.median, s.max, s.outliers),
            (1.5, 1.5, 1.5, 1.5, 0)
        );
    }

    #[test]
    fn the_median_of_an_even_count_is_the_mean_of_the_middle_two() {
        assert_eq!(median(&[3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&[4.0, 1.0, 3.0, 2.0]), 2.5);
    }

    #[test]
    fn a_far_trial_is_an_outlier_and_near_ones_are_not() {
        // median 3, deviations 2, 1, 0, 1, 97: MAD 1, so only 100 is beyond 3 MADs.
        let xs = [1.0, 2.0, 3.0, 4.0, 100.0];
        assert_eq!(mad(&xs), 1.0);
        assert_eq!(outliers(&xs), 1);
        // exactly 3 MADs away is not an outlier.
        assert_eq!(outliers(&[1.0, 2.0, 3.0, 4.0, 6.0]), 0);
    }

    #[test]
    fn with_most_trials_equal_any_different_trial_is_an_outlier() {
        assert_eq!(outliers(&[1.0, 1.0, 1.0, 1.25]), 1);
        assert_eq!(outliers(&[1.0, 1.0, 1.0]), 0);
    }

    #[test]
    fn stats_of_no_trials_are_none_and_of_some_are_complete() {
        assert_eq!(Stats::of(&[]), None);
        let s = Stats::of(&[3.0, 1.0, 2.0, 10.0]).unwrap();
        assert_eq!(s.mean, 4.0);
        assert_eq!(s.min, 1.0);
        assert_eq!(s.max, 10.0);
        assert_eq!(s.median, 2.5);
        // deviations 0.5, 1.5, 0.5, 7.5: MAD 1, so 10 is an outlier.
        assert_eq!(s.outliers, 1);
        assert_eq!(s.stddev, sample_stddev(&[3.0, 1.0, 2.0, 10.0]));
    }
}
