//! What `validate` prints: a table per data set, the slopes and the verdicts as text
//! ([`lines`]), or one JSON object ([`Json`]).

use serde::Serialize;

use super::Validation;
use super::verdict::{Check, FRONT_SHIFT, FRONT_WINDOW, PointCheck, SLOPE_WINDOW, Slopes, Verdict};

/// The shift, and why, in one sentence (printed, and in the book's validation page).
pub const SHIFT_NOTE: &str = "the experiment's early front lags (the gate takes time to \
    remove) while converged SPH leads by dT = 0.2-0.25, so, as Lethe's validation does, the \
    simulated front is shifted right by T = 0.175 before positions are compared";

/// `validate --json`: the run, the verdicts with their measured values, every point's error.
#[derive(Debug, Serialize)]
pub struct Json<'a> {
    tool: &'static str,
    resolution: usize,
    fluid_particles: usize,
    walls: usize,
    neighbors: &'static str,
    strategy: &'static str,
    cores: usize,
    chunks: Option<usize>,
    steps: usize,
    simulated_s: f64,
    wall_s: f64,
    cpu_s: f64,
    passed: bool,
    front_shift: f64,
    verdicts: Vec<JsonVerdict>,
    slope: &'a Slopes,
    surge_front: &'a [PointCheck],
    column_height: &'a [PointCheck],
}

#[derive(Debug, Serialize)]
struct JsonVerdict {
    name: Check,
    description: &'static str,
    measured: f64,
    tolerance: f64,
    points: usize,
    pass: bool,
}

impl<'a> Json<'a> {
    /// The JSON object of `v`.
    pub fn of(v: &'a Validation) -> Json<'a> {
        let info = v.strategy.info();
        Json {
            tool: "bench-sph validate",
            resolution: v.resolution,
            fluid_particles: v.fluid,
            walls: v.walls,
            neighbors: "grid",
            strategy: info.name,
            cores: info.effective_cores(v.config.cores),
            chunks: info.effective_chunks(v.config.chunks),
            steps: v.steps,
            simulated_s: v.simulated_s,
            wall_s: v.elapsed.wall_s,
            cpu_s: v.elapsed.cpu_s,
            passed: v.outcome.passed(),
            front_shift: FRONT_SHIFT,
            verdicts: v
                .outcome
                .verdicts
                .iter()
                .map(|x| JsonVerdict {
                    name: x.check,
                    description: x.check.describe(),
                    measured: x.measured,
                    tolerance: x.tolerance,
                    points: x.points,
                    pass: x.pass,
                })
                .collect(),
            slope: &v.outcome.slopes,
            surge_front: &v.outcome.surge_front,
            column_height: &v.outcome.column_height,
        }
    }
}

/// The printed summary of `v`.
pub fn lines(v: &Validation) -> Vec<String> {
    let info = v.strategy.info();
    let chunks = info
        .effective_chunks(v.config.chunks)
        .map_or_else(|| "n/a".to_owned(), |c| c.to_string());
    let s = &v.scales;
    let mut out = vec![
        format!(
            "validate: wcsph dam break against Martin & Moyce (1952), square column n\u{b2} = 2; \
             R = {}: {} fluid + {} wall particles, grid search, strategy {} (cores {}, chunks {chunks})",
            v.resolution,
            v.fluid,
            v.walls,
            info.name,
            info.effective_cores(v.config.cores)
        ),
        format!(
            "ran {} steps to t = {:.4} s (T = {:.3}, \u{3c4} = {:.3}) in {:.3} s wall, {:.3} s CPU \
             (the step loop)",
            v.steps,
            v.simulated_s,
            s.front_time(v.simulated_s),
            s.column_time(v.simulated_s),
            v.elapsed.wall_s,
            v.elapsed.cpu_s
        ),
        String::new(),
        format!("surge front: Z_exp(T) against the simulation at T - {FRONT_SHIFT}: {SHIFT_NOTE}"),
        format!(
            "{:>6} {:>7} {:>16} {:>9}",
            "T", "Z_exp", "Z_sim(T-0.175)", "error"
        ),
    ];
    let front_window = format!(
        "outside T in [{:.1}, {:.1}]",
        FRONT_WINDOW.0, FRONT_WINDOW.1
    );
    out.extend(
        v.outcome
            .surge_front
            .iter()
            .map(|p| point_line(p, 16, &front_window)),
    );
    out.push("column height at the wall: H_exp(\u{3c4}) against H_sim(\u{3c4})".to_owned());
    out.push(format!(
        "{:>6} {:>7} {:>16} {:>9}",
        "tau", "H_exp", "H_sim(tau)", "error"
    ));
    out.extend(
        v.outcome
            .column_height
            .iter()
            .map(|p| point_line(p, 16, "outside tau <= 2")),
    );
    let sl = &v.outcome.slopes;
    out.push(format!(
        "front slope dZ/dT over T in [{}, {}]: experiment {:.4} ({} points), simulation {:.4} \
         ({} samples), difference {}",
        SLOPE_WINDOW.0,
        SLOPE_WINDOW.1,
        sl.experiment,
        sl.experiment_points,
        sl.simulation,
        sl.simulation_samples,
        percent(sl.difference, true)
    ));
    out.push(String::new());
    out.extend(v.outcome.verdicts.iter().map(verdict_line));
    out
}

/// A row of a per-point table: time, experiment, simulation, signed error; a note when the
/// point is outside its verdict's window or beyond the simulated times.
fn point_line(p: &PointCheck, width: usize, outside: &str) -> String {
    let head = format!("{:>6.2} {:>7.2}", p.time, p.experiment);
    match (p.simulation, p.error) {
        (Some(sim), Some(err)) => {
            let note = if p.in_window {
                String::new()
            } else {
                format!("  ({outside})")
            };
            format!("{head} {sim:>width$.3} {:>9}{note}", percent(err, true))
        }
        _ => format!("{head} {:>width$}", "not reached"),
    }
}

/// `PASS`/`FAIL`, the check, what was measured.
pub fn verdict_line(v: &Verdict) -> String {
    let word = if v.pass { "PASS" } else { "FAIL" };
    let measured = match v.check {
        Check::FrontSlope => format!("difference {}", percent(v.measured, false)),
        _ => format!(
            "worst {} over {} points",
            percent(v.measured, false),
            v.points
        ),
    };
    format!("{word} {}: {measured}", v.check.describe())
}

/// A fraction as a percentage with one decimal (`+1.2 %` when `signed`), or `n/a` for NaN.
fn percent(f: f64, signed: bool) -> String {
    if f.is_nan() {
        "n/a".to_owned()
    } else if signed {
        format!("{:+.1} %", 100.0 * f)
    } else {
        format!("{:.1} %", 100.0 * f)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_point_line_shows_the_signed_error_or_why_it_is_not_counted() {
        let p = PointCheck {
            time: 0.41,
            experiment: 1.11,
            simulated_time: 0.235,
            simulation: Some(1.05),
            error: Some(-0.054),
            in_window: false,
        };
        assert_eq!(
            point_line(&p, 16, "outside T in [0.8, 3.0]"),
            "  0.41    1.11            1.050    -5.4 %  (outside T in [0.8, 3.0])"
        );
        let q = PointCheck {
            simulation: None,
            error: None,
            in_window: true,
            ..p
        };
        assert_eq!(point_line(&q, 16, ""), "  0.41    1.11      not reached");
    }

    #[test]
    fn verdict_lines_start_with_pass_or_fail() {
        let v = Verdict {
            check: Check::ColumnHeight,
            measured: 0.0712,
            tolerance: 0.06,
            points: 9,
            pass: false,
        };
        assert_eq!(
            verdict_line(&v),
            "FAIL column height H(tau) within 6 % for tau <= 2: worst 7.1 % over 9 points"
        );
        let s = Verdict {
            check: Check::FrontSlope,
            measured: f64::NAN,
            pass: false,
            ..v
        };
        assert!(verdict_line(&s).ends_with("difference n/a"));
    }
}
