//! 95 % confidence intervals with shown coverage at 3–10 rounds: pure functions of the times.
//!
//! - **A cell's time**: the Student-t interval of the mean of the logarithms of its k run
//!   times, m ± t(k−1) · s / √k, exponentiated: an interval for the cell's typical
//!   (geometric-mean) time. Timing noise is multiplicative and close to log-normal, where this
//!   is exact; an interval on the times themselves would reach below zero for a noisy cell of
//!   three runs. For noise of a few percent the geometric and arithmetic means differ by far
//!   less than the interval's width (the coverage test, `sweep/coverage.rs`, measures it).
//! - **A ratio of two cells' times** (a speedup, or strategy A against strategy B): the runs
//!   are **paired by round** — round r of each cell ran in the same shuffled round, minutes or
//!   less apart — and the estimate is the geometric mean of the per-round ratios, with the
//!   Student-t interval of their logarithms, exponentiated. Drift that moves both runs of a
//!   round cancels in their ratio; what is left varies from round to round, and the interval's
//!   width comes from that variation.
//!
//! Why not the percentile bootstrap the first versions used: with 3–5 trials it covered a true
//! mean in only 70–84 % of simulated sweeps (over 3 trials its "95 %" interval is [min, max]),
//! and resampling two cells independently ignores the pairing that makes drift cancel. Why not
//! BCa: it needs more samples than a sweep's rounds to estimate its acceleration.
//!
//! Fewer than [`MIN_ROUNDS`] values give no interval (and so, in the report, no finding): the
//! t quantile for one degree of freedom is 12.7, an interval that says nothing.

use statrs::distribution::{ContinuousCDF, StudentsT};

use super::stats::{CONFIDENCE, Interval, mean, sample_stddev};

/// The fewest values (runs, or paired rounds) that get an interval.
pub const MIN_ROUNDS: usize = 3;

/// The two-sided [`CONFIDENCE`] quantile of Student's t with `df` degrees of freedom
/// (4.303 for 2, 2.776 for 4, 1.960 in the limit).
pub fn t_quantile(df: usize) -> f64 {
    let upper = 1.0 - (1.0 - CONFIDENCE) / 2.0;
    StudentsT::new(0.0, 1.0, df as f64)
        .expect("one degree of freedom or more is a valid t distribution")
        .inverse_cdf(upper)
}

/// The interval of the typical time of `times` (seconds, positive): [`ratio`]'s interval of
/// their geometric mean; `None` for fewer than [`MIN_ROUNDS`] values or a time that is not
/// positive and finite.
pub fn mean_interval(times: &[f64]) -> Option<Interval> {
    ratio(times)?.interval
}

/// A ratio estimated from paired rounds: the geometric mean of the per-round ratios and its
/// interval.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ratio {
    /// The geometric mean of the per-round ratios.
    pub value: f64,
    /// Its interval (`None` with fewer than [`MIN_ROUNDS`] rounds).
    pub interval: Option<Interval>,
    /// The rounds it rests on.
    pub rounds: usize,
}

impl Ratio {
    /// Whether the interval excludes 1: the two sides differ, by this sweep's evidence.
    pub fn resolved(&self) -> bool {
        self.interval.is_some_and(|i| !i.contains(1.0))
    }
}

/// The geometric mean of `ratios` (each positive and finite) with the Student-t interval of
/// their logarithms, exponentiated; `None` when empty or when a value is not positive and
/// finite.
pub fn ratio(ratios: &[f64]) -> Option<Ratio> {
    if ratios.is_empty() || ratios.iter().any(|r| !(r.is_finite() && *r > 0.0)) {
        return None;
    }
    let logs: Vec<f64> = ratios.iter().map(|r| r.ln()).collect();
    let centre = mean(&logs);
    let interval = (logs.len() >= MIN_ROUNDS).then(|| {
        let s = sample_stddev(&logs).expect("three values or more");
        let half = t_quantile(logs.len() - 1) * s / (logs.len() as f64).sqrt();
        Interval {
            low: (centre - half).exp(),
            high: (centre + half).exp(),
        }
    });
    Some(Ratio {
        value: centre.exp(),
        interval,
        rounds: logs.len(),
    })
}

/// The per-round ratios `num[r] / den[r]` of the rounds both sides ran, in round order;
/// each side is (round, seconds) pairs with each round at most once.
pub fn paired(num: &[(usize, f64)], den: &[(usize, f64)]) -> Vec<f64> {
    let mut out: Vec<(usize, f64)> = num
        .iter()
        .filter_map(|&(round, n)| {
            let &(_, d) = den.iter().find(|(r, _)| *r == round)?;
            Some((round, n / d))
        })
        .collect();
    out.sort_by_key(|&(round, _)| round);
    out.into_iter().map(|(_, r)| r).collect()
}

/// The ratio of `num`'s times to `den`'s, paired by round (see [`paired`] and [`ratio`]):
/// a speedup when `num` is the `seq` reference.
pub fn paired_ratio(num: &[(usize, f64)], den: &[(usize, f64)]) -> Option<Ratio> {
    ratio(&paired(num, den))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn t_quantiles_match_the_tables() {
        for (df, want) in [
            (1, 12.706),
            (2, 4.303),
            (4, 2.776),
            (9, 2.262),
            (1000, 1.962),
        ] {
            assert!((t_quantile(df) - want).abs() < 1e-3, "df {df}");
        }
    }

    #[test]
    fn the_time_interval_is_student_t_on_the_logs_and_needs_three_values() {
        // logs 0, ln 2, ln 4: mean ln 2, s ln 2, k 3: 2 · exp(± 4.303 · ln 2 / √3).
        let i = mean_interval(&[1.0, 2.0, 4.0]).unwrap();
        let factor = (4.302_652_729_749_464 * 2f64.ln() / 3f64.sqrt()).exp();
        assert!((i.low - 2.0 / factor).abs() < 1e-9 && (i.high - 2.0 * factor).abs() < 1e-9);
        // However noisy, never below zero.
        assert!(mean_interval(&[0.1, 5.0, 0.2]).unwrap().low > 0.0);
        assert_eq!(mean_interval(&[1.0, 2.0]), None);
        let same = mean_interval(&[2.0, 2.0, 2.0]).unwrap();
        assert!((same.low - 2.0).abs() < 1e-12 && (same.high - 2.0).abs() < 1e-12);
    }

    #[test]
    fn a_ratio_is_the_geometric_mean_with_an_interval_symmetric_in_logs() {
        let r = ratio(&[2.0, 8.0, 4.0]).unwrap();
        assert!((r.value - 4.0).abs() < 1e-12);
        let i = r.interval.unwrap();
        assert!((i.low * i.high - 16.0).abs() < 1e-9, "{i:?}");
        assert!(i.low < 4.0 && i.high > 4.0);
        assert_eq!(r.rounds, 3);
        // Three rounds this far apart do not exclude 1; three close together do.
        assert!(!r.resolved());
        assert!(ratio(&[3.0, 4.0, 5.0]).unwrap().resolved());
        // Two rounds: an estimate, no interval, so nothing is resolved.
        let two = ratio(&[2.0, 2.2]).unwrap();
        assert_eq!(two.interval, None);
        assert!(!two.resolved());
        assert_eq!(ratio(&[]), None);
        assert_eq!(ratio(&[1.0, 0.0, 1.0]), None);
        assert_eq!(ratio(&[1.0, f64::NAN, 1.0]), None);
    }

    #[test]
    fn an_interval_that_contains_one_is_not_resolved() {
        let r = ratio(&[0.9, 1.1, 1.0, 1.05]).unwrap();
        assert!(!r.resolved(), "{r:?}");
    }

    #[test]
    fn rounds_are_paired_by_number_and_unmatched_rounds_left_out() {
        let seq = [(1, 1.0), (2, 1.2), (3, 0.9), (4, 1.0)];
        let cell = [(3, 0.45), (1, 0.5), (2, 0.6)];
        assert_eq!(paired(&seq, &cell), [2.0, 2.0, 2.0]);
        let r = paired_ratio(&seq, &cell).unwrap();
        assert_eq!(r.rounds, 3);
        // Every round's ratio is 2: drift between rounds (1.2 vs 0.9) left no trace.
        assert!((r.value - 2.0).abs() < 1e-12);
        let i = r.interval.unwrap();
        assert!((i.low - 2.0).abs() < 1e-12 && (i.high - 2.0).abs() < 1e-12);
    }
}
