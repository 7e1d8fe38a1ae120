//! Where a trial's seconds come from: the clock, or — **for tests only** — a fixed list.
//!
//! The hidden option `--fake-timings LIST` (comma-separated items `WALL` or `WALL:CPU`, in
//! seconds; CPU defaults to WALL) replaces the measured times of every timed trial, so tests
//! can check the statistics exactly. The simulation still runs and its checksums are still
//! checked; only the numbers written are replaced. Trial `t` (from 0) of the cell at position
//! `c` of the plan gets item `(c · trials + t) mod len`, so a resumed sweep gets the same
//! numbers as an uninterrupted one. A sweep with fake timings records the list in
//! `meta.json` and says so in its output: such numbers never pass for measurements.

use crate::clock::Elapsed;

/// Why a fake-timings list could not be read.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("bad --fake-timings item '{0}': expected WALL or WALL:CPU seconds, WALL > 0, CPU >= 0")]
pub struct BadFakeTiming(pub String);

/// The source of trial times.
#[derive(Debug, Clone, PartialEq)]
pub enum Timing {
    /// The measured times (the only mode for real sweeps).
    Real,
    /// Test only: times taken in turn from this (non-empty) list.
    Fake(Vec<Elapsed>),
}

impl Timing {
    /// `Real`, or `Fake` from a `--fake-timings` list.
    pub fn new(fake: Option<&str>) -> Result<Timing, BadFakeTiming> {
        let Some(spec) = fake else {
            return Ok(Timing::Real);
        };
        let item = |s: &str| -> Result<Elapsed, BadFakeTiming> {
            let bad = || BadFakeTiming(s.to_owned());
            let number = |v: &str| v.trim().parse::<f64>().map_err(|_| bad());
            let (wall_s, cpu_s) = match s.split_once(':') {
                Some((w, c)) => (number(w)?, number(c)?),
                None => (number(s)?, number(s)?),
            };
            if !(wall_s.is_finite() && wall_s > 0.0 && cpu_s.is_finite() && cpu_s >= 0.0) {
                return Err(bad());
            }
            Ok(Elapsed { wall_s, cpu_s })
        };
        let list = spec.split(',').map(item).collect::<Result<Vec<_>, _>>()?;
        Ok(Timing::Fake(list))
    }

    /// The times to record for trial `trial` (from 0) of the cell at `cell_index` in the plan.
    pub fn trial_time(
        &self,
        measured: Elapsed,
        cell_index: usize,
        trials: usize,
        trial: usize,
    ) -> Elapsed {
        match self {
            Timing::Real => measured,
            Timing::Fake(list) => list[(cell_index * trials + trial) % list.len()],
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const MEASURED: Elapsed = Elapsed {
        wall_s: 9.0,
        cpu_s: 9.0,
    };

    #[test]
    fn real_timing_keeps_the_measurement() {
        assert_eq!(
            Timing::new(None).unwrap().trial_time(MEASURED, 3, 5, 2),
            MEASURED
        );
    }

    #[test]
    fn fake_timings_are_taken_in_turn_by_plan_position() {
        let t = Timing::new(Some("1,2:0.5,3")).unwrap();
        let at = |cell, trial| t.trial_time(MEASURED, cell, 2, trial);
        assert_eq!(
            at(0, 0),
            Elapsed {
                wall_s: 1.0,
                cpu_s: 1.0
            }
        );
        assert_eq!(
            at(0, 1),
            Elapsed {
                wall_s: 2.0,
                cpu_s: 0.5
            }
        );
        assert_eq!(at(1, 0).wall_s, 3.0);
        assert_eq!(at(1, 1).wall_s, 1.0);
    }

    #[test]
    fn malformed_fake_timings_are_refused() {
        for bad in ["", "x", "1,,2", "0", "-1", "1:-1", "inf", "1:2:3"] {
            assert!(Timing::new(Some(bad)).is_err(), "{bad}");
        }
    }
}
