//! How REPORT.md writes numbers: never more than three significant digits (a mean of five
//! noisy trials does not know its fourth digit); intervals of times as `[low–high]`, relative
//! results as hyperfine writes them, `1.62 ± 0.04×` (± the larger half of the 95 % interval).

pub use sph_harness::output::digits::sig;
use sph_harness::results::intervals::Ratio;
use sph_harness::results::stats::Interval;

/// Seconds: [`sig`].
pub fn secs(v: f64) -> String {
    sig(v)
}

/// `mean ± stddev`, the stddev to as many decimals as the mean shows (`mean` alone without a
/// stddev).
pub fn mean_sd(mean: f64, sd: Option<f64>) -> String {
    let m = sig(mean);
    match sd {
        Some(sd) => format!("{m} ± {}", like(&m, sd)),
        None => m,
    }
}

/// `x` to as many decimals as `shown` (a number as [`sig`] wrote it) has.
fn like(shown: &str, x: f64) -> String {
    let places = shown.split_once('.').map_or(0, |(_, d)| d.len());
    format!("{x:.places$}")
}

/// A ratio and its 95 % interval as hyperfine writes them: `1.62 ± 0.04×`, ± the larger
/// half of the interval (which is not symmetric on a linear scale) to the value's decimals;
/// `1.62×` without an interval.
pub fn plus_minus(value: f64, i: Option<Interval>) -> String {
    let v = sig(value);
    match i {
        Some(i) => format!("{v} ± {}×", like(&v, (value - i.low).max(i.high - value))),
        None => format!("{v}×"),
    }
}

/// How much faster `r` (a time ratio other / this, paired by round) says this is than
/// `other`: `1.62 ± 0.04× faster than seq`, or below 1, `1.20 ± 0.02× slower than seq`.
pub fn faster(r: &Ratio, other: &str) -> String {
    if r.value >= 1.0 {
        return format!("{} faster than {other}", plus_minus(r.value, r.interval));
    }
    let inverse = r.interval.map(|i| Interval {
        low: 1.0 / i.high,
        high: 1.0 / i.low,
    });
    format!("{} slower than {other}", plus_minus(1.0 / r.value, inverse))
}

/// A speedup: `1.84×`.
pub fn times(v: f64) -> String {
    format!("{}×", sig(v))
}

/// A percentage: `8.3 %`.
pub fn percent(v: f64) -> String {
    format!("{} %", sig(v))
}

/// ` [low–high]`, or nothing without an interval.
pub fn interval(i: Option<Interval>) -> String {
    i.map_or_else(String::new, |i| {
        format!(" [{}–{}]", sig(i.low), sig(i.high))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn report_numbers_have_at_most_three_significant_digits() {
        assert_eq!(times(1.8365), "1.84×");
        assert_eq!(mean_sd(1.0886, Some(0.0218)), "1.09 ± 0.02");
        assert_eq!(percent(8.333), "8.33 %");
        let i = Interval {
            low: 0.40123,
            high: 0.4234,
        };
        assert_eq!(interval(Some(i)), " [0.401–0.423]");
    }

    #[test]
    fn relative_results_read_like_hyperfine_with_the_larger_half_of_the_interval() {
        let i = |low, high| Some(Interval { low, high });
        assert_eq!(plus_minus(1.62, i(1.59, 1.66)), "1.62 ± 0.04×");
        assert_eq!(plus_minus(16.2, i(15.0, 16.4)), "16.2 ± 1.2×");
        assert_eq!(plus_minus(2.0, i(2.0, 2.0)), "2.00 ± 0.00×");
        assert_eq!(plus_minus(1.5, None), "1.50×");
        let r = |value, low, high| Ratio {
            value,
            interval: i(low, high),
            rounds: 3,
        };
        assert_eq!(
            faster(&r(1.25, 1.2, 1.3), "seq"),
            "1.25 ± 0.05× faster than seq"
        );
        // 0.8 [0.75–0.85] is 1.25 [1.18–1.33] the other way round.
        assert_eq!(
            faster(&r(0.8, 0.75, 0.85), "seq"),
            "1.25 ± 0.08× slower than seq"
        );
    }
}
