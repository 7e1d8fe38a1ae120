//! The comparison with the experiment, as pure functions of the simulated curves and the
//! tables: each experiment point's error, the front's slope, and three verdicts.
//!
//! 1. **Column height**: for every experiment point with τ ≤ 2, |H_sim(τ) − H_exp| / H_exp
//!    ≤ 6 % (H_sim linearly interpolated between samples).
//! 2. **Front slope**: the least-squares slope dZ/dT of the experiment's points with T in
//!    [1.5, 2.8] and that of the simulation's samples with T in [1.5, 2.8] differ by at most
//!    5 % of the experiment's.
//! 3. **Front position, shifted**: for every experiment point with T in [0.8, 3.0],
//!    |Z_sim(T − 0.175) − Z_exp| / Z_exp ≤ 10 %. The experiment's early front lags (the
//!    gate is pulled away, which takes time), while a converged simulation's front leads it
//!    by ΔT ≈ 0.2–0.25; Lethe's validation of the same case shifts the simulated times by
//!    +0.175, and so does this one: the simulated curve moved right by 0.175.
//!
//! An experiment point beyond the simulated times is "not reached": outside a verdict's window
//! it is only listed, inside it fails the verdict (its worst error is then unknown, NaN); a
//! verdict that counts no point at all fails too.

use serde::Serialize;

use super::data::{Experiment, Point};

/// τ up to which the column height is checked.
pub const COLUMN_TAU_MAX: f64 = 2.0;
/// The column height's tolerance, relative.
pub const COLUMN_TOLERANCE: f64 = 0.06;
/// T window of the front's slope.
pub const SLOPE_WINDOW: (f64, f64) = (1.5, 2.8);
/// The slope's tolerance, relative to the experiment's.
pub const SLOPE_TOLERANCE: f64 = 0.05;
/// How far the simulated front is shifted right in T before comparing positions.
pub const FRONT_SHIFT: f64 = 0.175;
/// T window of the front's position.
pub const FRONT_WINDOW: (f64, f64) = (0.8, 3.0);
/// The front position's tolerance, relative.
pub const FRONT_TOLERANCE: f64 = 0.10;

/// One of the three checks.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Check {
    /// H(τ) within 6 % for τ ≤ 2.
    ColumnHeight,
    /// dZ/dT over T in [1.5, 2.8] within 5 %.
    FrontSlope,
    /// Z_sim(T − 0.175) within 10 % of Z_exp(T) for T in [0.8, 3.0].
    FrontPosition,
}

impl Check {
    /// What the check asks, in words.
    pub fn describe(self) -> &'static str {
        match self {
            Check::ColumnHeight => "column height H(tau) within 6 % for tau <= 2",
            Check::FrontSlope => "front slope dZ/dT over T in [1.5, 2.8] within 5 %",
            Check::FrontPosition => {
                "front Z_sim(T - 0.175) within 10 % of Z_exp(T) for T in [0.8, 3.0]"
            }
        }
    }
}

/// One experiment point against the simulation.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PointCheck {
    /// The experiment's time (T or τ).
    pub time: f64,
    /// The experiment's value (Z or H).
    pub experiment: f64,
    /// The simulation's time compared with it (T − 0.175 for the front, τ for the column).
    pub simulated_time: f64,
    /// The simulation's value there, interpolated; `None`: not reached.
    pub simulation: Option<f64>,
    /// (simulation − experiment) / experiment; `None`: not reached.
    pub error: Option<f64>,
    /// Whether the point lies in its verdict's window.
    pub in_window: bool,
}

impl PointCheck {
    /// Whether the point is part of its verdict: in the window and reached.
    pub fn counted(&self) -> bool {
        self.in_window && self.error.is_some()
    }
}

/// The front's least-squares slopes dZ/dT over [`SLOPE_WINDOW`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Slopes {
    /// The experiment's, over its points in the window.
    pub experiment: f64,
    /// The simulation's, over its samples in the window.
    pub simulation: f64,
    /// (simulation − experiment) / experiment.
    pub difference: f64,
    /// Experiment points in the window.
    pub experiment_points: usize,
    /// Simulation samples in the window.
    pub simulation_samples: usize,
}

/// A check's outcome.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Verdict {
    /// Which check.
    pub check: Check,
    /// What was measured: the largest |relative error| over the counted points, or the
    /// slopes' |relative difference| (NaN when nothing could be measured).
    pub measured: f64,
    /// The largest `measured` that passes.
    pub tolerance: f64,
    /// Experiment points the verdict counts.
    pub points: usize,
    /// Whether `measured` ≤ `tolerance` (false for NaN).
    pub pass: bool,
}

/// Everything the comparison found.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Outcome {
    /// Every surge-front point, in the table's order.
    pub surge_front: Vec<PointCheck>,
    /// Every column-height point, in the table's order.
    pub column_height: Vec<PointCheck>,
    /// The front's slopes.
    pub slopes: Slopes,
    /// Column height, front slope, front position.
    pub verdicts: [Verdict; 3],
}

impl Outcome {
    /// Whether every verdict passed.
    pub fn passed(&self) -> bool {
        self.verdicts.iter().all(|v| v.pass)
    }

    /// The verdicts that failed.
    pub fn failed(&self) -> Vec<Verdict> {
        self.verdicts.iter().copied().filter(|v| !v.pass).collect()
    }
}

/// Compares the simulated front Z(T) and column H(τ) (each in time order) with `experiment`.
pub fn evaluate(experiment: &Experiment, front: &[Point], column: &[Point]) -> Outcome {
    let in_front = |t: f64| (FRONT_WINDOW.0..=FRONT_WINDOW.1).contains(&t);
    let surge_front = compare(&experiment.surge_front, front, -FRONT_SHIFT, in_front);
    let column_height = compare(&experiment.column_height, column, 0.0, |tau| {
        tau <= COLUMN_TAU_MAX
    });
    let in_slope = |p: &&Point| (SLOPE_WINDOW.0..=SLOPE_WINDOW.1).contains(&p.time);
    let exp: Vec<Point> = experiment
        .surge_front
        .iter()
        .filter(in_slope)
        .copied()
        .collect();
    let sim: Vec<Point> = front.iter().filter(in_slope).copied().collect();
    let (e, s) = (slope(&exp), slope(&sim));
    let slopes = Slopes {
        experiment: e,
        simulation: s,
        difference: (s - e) / e,
        experiment_points: exp.len(),
        simulation_samples: sim.len(),
    };
    let verdicts = [
        points_verdict(Check::ColumnHeight, &column_height, COLUMN_TOLERANCE),
        verdict(
            Check::FrontSlope,
            slopes.difference.abs(),
            SLOPE_TOLERANCE,
            exp.len(),
        ),
        points_verdict(Check::FrontPosition, &surge_front, FRONT_TOLERANCE),
    ];
    Outcome {
        surge_front,
        column_height,
        slopes,
        verdicts,
    }
}

/// Each experiment point against the simulation at its time + `offset`.
fn compare(
    experiment: &[Point],
    simulation: &[Point],
    offset: f64,
    in_window: impl Fn(f64) -> bool,
) -> Vec<PointCheck> {
    experiment
        .iter()
        .map(|p| {
            let simulated_time = p.time + offset;
            let simulation = interpolate(simulation, simulated_time);
            PointCheck {
                time: p.time,
                experiment: p.value,
                simulated_time,
                simulation,
                error: simulation.map(|s| (s - p.value) / p.value),
                in_window: in_window(p.time),
            }
        })
        .collect()
}

fn points_verdict(check: Check, points: &[PointCheck], tolerance: f64) -> Verdict {
    let errors = points
        .iter()
        .filter(|p| p.counted())
        .filter_map(|p| p.error);
    let (count, worst) = errors.fold((0, 0f64), |(n, w), e| (n + 1, w.max(e.abs())));
    let unreached = points.iter().any(|p| p.in_window && p.error.is_none());
    let measured = if count == 0 || unreached {
        f64::NAN
    } else {
        worst
    };
    verdict(check, measured, tolerance, count)
}

fn verdict(check: Check, measured: f64, tolerance: f64, points: usize) -> Verdict {
    Verdict {
        check,
        measured,
        tolerance,
        points,
        // NaN (nothing measured) fails.
        pass: measured <= tolerance,
    }
}

/// The value of `curve` (time order, times non-decreasing) at `time`, linearly interpolated
/// between the samples around it; `None` outside the curve's times.
pub fn interpolate(curve: &[Point], time: f64) -> Option<f64> {
    let i = curve.partition_point(|p| p.time < time);
    let b = curve.get(i)?;
    if b.time == time {
        return Some(b.value);
    }
    let a = curve.get(i.checked_sub(1)?)?;
    Some(a.value + (b.value - a.value) * ((time - a.time) / (b.time - a.time)))
}

/// The least-squares slope of value against time over `points` (NaN for fewer than two
/// distinct times).
pub fn slope(points: &[Point]) -> f64 {
    let n = points.len() as f64;
    if points.len() < 2 {
        return f64::NAN;
    }
    let mean_t = points.iter().map(|p| p.time).sum::<f64>() / n;
    let mean_v = points.iter().map(|p| p.value).sum::<f64>() / n;
    let (sxy, sxx) = points.iter().fold((0.0, 0.0), |(sxy, sxx), p| {
        let dt = p.time - mean_t;
        (sxy + dt * (p.value - mean_v), sxx + dt * dt)
    });
    if sxx == 0.0 { f64::NAN } else { sxy / sxx }
}

/// Points from (time, value) pairs, for tests.
#[cfg(any(test, feature = "testing"))]
pub fn pts(v: &[(f64, f64)]) -> Vec<Point> {
    v.iter()
        .map(|&(time, value)| Point { time, value })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interpolation_is_linear_between_samples_and_none_outside_them() {
        let c = pts(&[(0.0, 0.0), (1.0, 2.0), (1.0, 2.0), (2.0, 2.0)]);
        assert_eq!(interpolate(&c, 0.0), Some(0.0));
        assert_eq!(interpolate(&c, 0.25), Some(0.5));
        assert_eq!(interpolate(&c, 1.0), Some(2.0));
        assert_eq!(interpolate(&c, 1.5), Some(2.0));
        assert_eq!(interpolate(&c, 2.0), Some(2.0));
        assert_eq!(interpolate(&c, 2.5), None);
        assert_eq!(interpolate(&c, -0.5), None);
        assert_eq!(interpolate(&[], 0.0), None);
    }

    #[test]
    fn the_slope_is_the_least_squares_fit() {
        assert_eq!(slope(&pts(&[(0.0, 1.0), (1.0, 4.0), (2.0, 7.0)])), 3.0);
        // Residuals +1, -2, +1 around y = 2x leave the slope 2.
        assert_eq!(slope(&pts(&[(0.0, 1.0), (1.0, 0.0), (2.0, 5.0)])), 2.0);
        assert!(slope(&pts(&[(1.0, 1.0)])).is_nan());
        assert!(slope(&pts(&[(1.0, 1.0), (1.0, 2.0)])).is_nan());
    }

    /// An experiment whose front is Z = 2T (T = 0.5, 1, 1.5, 2, 2.5, 3, 3.5) and whose column
    /// is H = 1 − τ/4 (τ = 1, 2, 3).
    fn experiment() -> Experiment {
        Experiment {
            surge_front: pts(&[
                (0.5, 1.0),
                (1.0, 2.0),
                (1.5, 3.0),
                (2.0, 4.0),
                (2.5, 5.0),
                (3.0, 6.0),
                (3.5, 7.0),
            ]),
            column_height: pts(&[(1.0, 0.75), (2.0, 0.5), (3.0, 0.25)]),
        }
    }

    /// A simulated front Z = 2(T + 0.175) · (1 + e) sampled every 0.25 from 0 to 3.25 (the
    /// experiment's point at 3.5 lies beyond it), and a column H = (1 − τ/4)(1 + c) to τ = 2.5.
    fn simulation(e: f64, c: f64) -> (Vec<Point>, Vec<Point>) {
        let front = (0..=13)
            .map(|k| {
                let t = k as f64 * 0.25;
                Point {
                    time: t,
                    value: 2.0 * (t + FRONT_SHIFT) * (1.0 + e),
                }
            })
            .collect();
        let column = (0..=10)
            .map(|k| {
                let tau = k as f64 * 0.25;
                Point {
                    time: tau,
                    value: (1.0 - tau / 4.0) * (1.0 + c),
                }
            })
            .collect();
        (front, column)
    }

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() < 1e-12
    }

    #[test]
    fn a_simulation_that_matches_the_experiment_passes_every_verdict() {
        let (front, column) = simulation(0.0, 0.0);
        let out = evaluate(&experiment(), &front, &column);
        assert!(out.passed(), "{out:#?}");
        let [h, s, z] = out.verdicts;
        // The column's points at τ = 1 and 2; τ = 3 is beyond τ ≤ 2 (and not reached).
        assert_eq!((h.check, h.points), (Check::ColumnHeight, 2));
        assert!(close(h.measured, 0.0));
        assert_eq!(out.column_height[2].simulation, None);
        // Slope over T = 1.5, 2.0, 2.5 (experiment) and 1.5 ..= 2.75 (simulation): both 2.
        assert_eq!((s.check, s.points), (Check::FrontSlope, 3));
        assert!(close(out.slopes.experiment, 2.0) && close(out.slopes.simulation, 2.0));
        assert_eq!(out.slopes.simulation_samples, 6);
        // Front points at T = 1, 1.5, 2, 2.5, 3 are in [0.8, 3.0]; 0.5 is outside it and 3.5
        // is compared at 3.325, beyond the samples.
        assert_eq!((z.check, z.points), (Check::FrontPosition, 5));
        assert!(close(z.measured, 0.0));
        let first = out.surge_front[0];
        assert!(!first.in_window && first.error.is_some_and(|e| close(e, 0.0)));
        assert!(close(first.simulated_time, 0.325));
        assert_eq!(out.surge_front[6].simulation, None);
        assert!(!out.surge_front[6].in_window);
    }

    #[test]
    fn errors_beyond_a_tolerance_fail_that_verdict_only() {
        // The column 7 % high (tolerance 6 %), the front 4 % long: its positions pass (10 %)
        // and its slope is 4 % steeper (5 %).
        let (front, column) = simulation(0.04, 0.07);
        let out = evaluate(&experiment(), &front, &column);
        let [h, s, z] = out.verdicts;
        assert!(!h.pass && close(h.measured, 0.07), "{h:?}");
        assert!(s.pass && close(s.measured, 0.04), "{s:?}");
        assert!(z.pass && close(z.measured, 0.04), "{z:?}");
        assert!(!out.passed());
        assert_eq!(out.failed(), [h]);
        let e = out.column_height[0].error.unwrap();
        assert!(close(e, 0.07), "signed: {e}");

        // A front 6 % long: the slope fails, the positions still pass.
        let (front, column) = simulation(0.06, 0.0);
        let out = evaluate(&experiment(), &front, &column);
        let failed: Vec<Check> = out.failed().iter().map(|v| v.check).collect();
        assert_eq!(failed, [Check::FrontSlope]);

        // 11 % short: both front verdicts fail.
        let (front, column) = simulation(-0.11, 0.0);
        let out = evaluate(&experiment(), &front, &column);
        let failed: Vec<Check> = out.failed().iter().map(|v| v.check).collect();
        assert_eq!(failed, [Check::FrontSlope, Check::FrontPosition]);
        assert!(close(out.slopes.difference, -0.11));
    }

    #[test]
    fn a_point_in_the_window_that_the_run_did_not_reach_fails_its_verdict() {
        // Exact values, but the column stops short of τ = 2 (the window's last point).
        let (front, column) = simulation(0.0, 0.0);
        let short: Vec<Point> = column.into_iter().filter(|p| p.time < 1.5).collect();
        let out = evaluate(&experiment(), &front, &short);
        let [h, s, z] = out.verdicts;
        assert!(!h.pass && h.measured.is_nan(), "{h:?}");
        assert_eq!(h.points, 1, "the point reached still counts");
        assert!(s.pass && z.pass);
    }

    #[test]
    fn a_verdict_with_no_point_reached_fails() {
        let short = pts(&[(0.0, 1.0), (0.1, 1.0)]);
        let out = evaluate(&experiment(), &short, &short);
        for v in out.verdicts {
            assert!(!v.pass && v.measured.is_nan(), "{v:?}");
        }
        assert_eq!(out.verdicts[0].points, 0);
    }
}
