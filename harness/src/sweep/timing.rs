//! Where a trial's numbers come from: the clock and the machine's counters, or — **for tests
//! only** — fixed lists.
//!
//! - The test hook `--fake-timings LIST` (comma-separated items `WALL` or `WALL:CPU`, in
//!   seconds; CPU defaults to WALL) replaces the measured times of every timed trial, so tests
//!   can check the statistics exactly.
//! - The test hook `--fake-contention LIST` (comma-separated shares in [0, 1] of the
//!   machine's capacity taken by other work) replaces the foreign-CPU readings: a trial given
//!   share f records `foreign_cpu_s` = f × hardware threads × its wall seconds, no steal, and a
//!   1-minute load of f × hardware threads; the busy-machine check before the plan reads the
//!   first item.
//!
//! The options that set them exist only in a `bench-sph` built with its `testing` cargo
//! feature (`bench_sph::cli`'s test hooks).
//! `--fake-timings` alone implies `--fake-contention 0` (a quiet machine), so a test's files do
//! not depend on what else the machine was doing.
//!
//! The simulation still runs and its checksums are still checked; only the numbers written
//! are replaced. Each timed run has a fixed number ([`fake_index`]): round r (from 1) of the
//! cell at position c of a plan of P cells is `c · K + r − 1` in the grid's K rounds and
//! `P · K + c · C + r − 1` in the confirmation's C rounds; it gets item `index mod len` of each
//! list, whatever order the rounds ran in, so a resumed sweep gets the same numbers as an
//! uninterrupted one. A sweep with fake numbers records the lists in `meta.json` and says so
//! in its output and report: such numbers never pass for measurements.

use crate::clock::Elapsed;
use crate::contention::Foreign;

/// Why a fake list could not be read.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum BadFake {
    /// A `--fake-timings` item.
    #[error("bad --fake-timings item '{0}': expected WALL or WALL:CPU seconds, WALL > 0, CPU >= 0")]
    Timing(String),
    /// A `--fake-contention` item.
    #[error("bad --fake-contention item '{0}': expected a share between 0 and 1")]
    Contention(String),
}

/// The source of trial numbers.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Timing {
    /// Test only: (wall, cpu) seconds taken in turn.
    times: Option<Vec<(f64, f64)>>,
    /// Test only: foreign shares of the machine taken in turn.
    shares: Option<Vec<f64>>,
}

/// The load readings a trial records.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Trial {
    /// Wall, CPU and foreign CPU over the step loop.
    pub elapsed: Elapsed,
    /// The 1-minute load average when the trial started.
    pub load1: Option<f64>,
}

impl Timing {
    /// Real measurements, or fake ones from `--fake-timings` / `--fake-contention` lists.
    pub fn new(fake_times: Option<&str>, fake_contention: Option<&str>) -> Result<Timing, BadFake> {
        let times = fake_times
            .map(|spec| {
                spec.split(',')
                    .map(time_item)
                    .collect::<Result<Vec<_>, _>>()
            })
            .transpose()?;
        let mut shares = fake_contention
            .map(|spec| {
                spec.split(',')
                    .map(share_item)
                    .collect::<Result<Vec<_>, _>>()
            })
            .transpose()?;
        // Fake times with real foreign readings would mix two windows: fake times come with a
        // quiet machine unless --fake-contention says otherwise.
        if times.is_some() && shares.is_none() {
            shares = Some(vec![0.0]);
        }
        Ok(Timing { times, shares })
    }

    /// The numbers to record for the run numbered `index` ([`fake_index`]), given what was
    /// measured.
    pub fn trial(&self, measured: Trial, index: usize, hardware_threads: usize) -> Trial {
        let pick = |len: usize| index % len;
        let mut out = measured;
        if let Some(list) = &self.times {
            let (wall_s, cpu_s) = list[pick(list.len())];
            out.elapsed.wall_s = wall_s;
            out.elapsed.cpu_s = cpu_s;
        }
        if let Some(list) = &self.shares {
            let share = list[pick(list.len())];
            let threads = hardware_threads as f64;
            out.elapsed.foreign = Some(Foreign {
                cpu_s: share * threads * out.elapsed.wall_s,
                steal_s: Some(0.0),
            });
            out.load1 = Some(share * threads);
        }
        out
    }

    /// Whether foreign CPU readings are fake (`--fake-contention`, or implied by
    /// `--fake-timings`).
    pub fn fakes_contention(&self) -> bool {
        self.shares.is_some()
    }

    /// Test only: the busy hardware threads the check before the plan should see (`None`:
    /// measure them).
    pub fn fake_busy_threads(&self, hardware_threads: usize) -> Option<f64> {
        self.shares
            .as_ref()
            .map(|list| list[0] * hardware_threads as f64)
    }
}

/// The fixed number of round `round` (from 1) of the cell at plan position `cell` in `phase`,
/// for a plan of `cells` cells with `trials` grid rounds and `confirm_rounds` confirmation
/// rounds (see the module docs).
pub fn fake_index(
    phase: crate::results::rows::Phase,
    cell: usize,
    round: usize,
    cells: usize,
    trials: usize,
    confirm_rounds: usize,
) -> usize {
    use crate::results::rows::Phase;
    match phase {
        Phase::Grid => cell * trials + round - 1,
        Phase::Confirm => cells * trials + cell * confirm_rounds + round - 1,
    }
}

fn time_item(s: &str) -> Result<(f64, f64), BadFake> {
    let bad = || BadFake::Timing(s.to_owned());
    let number = |v: &str| v.trim().parse::<f64>().map_err(|_| bad());
    let (wall_s, cpu_s) = match s.split_once(':') {
        Some((w, c)) => (number(w)?, number(c)?),
        None => (number(s)?, number(s)?),
    };
    if !(wall_s.is_finite() && wall_s > 0.0 && cpu_s.is_finite() && cpu_s >= 0.0) {
        return Err(bad());
    }
    Ok((wall_s, cpu_s))
}

fn share_item(s: &str) -> Result<f64, BadFake> {
    match s.trim().parse::<f64>() {
        Ok(v) if (0.0..=1.0).contains(&v) => Ok(v),
        _ => Err(BadFake::Contention(s.to_owned())),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const MEASURED: Trial = Trial {
        elapsed: Elapsed {
            wall_s: 9.0,
            cpu_s: 9.0,
            foreign: None,
        },
        load1: Some(0.5),
    };

    #[test]
    fn real_timing_keeps_the_measurement() {
        let t = Timing::new(None, None).unwrap();
        assert_eq!(t.trial(MEASURED, 17, 2), MEASURED);
        assert!(!t.fakes_contention());
        assert_eq!(t.fake_busy_threads(2), None);
    }

    #[test]
    fn fake_timings_are_taken_in_turn_by_plan_position() {
        let t = Timing::new(Some("1,2:0.5,3"), None).unwrap();
        let at = |cell: usize, trial: usize| t.trial(MEASURED, cell * 2 + trial, 2).elapsed;
        assert_eq!((at(0, 0).wall_s, at(0, 0).cpu_s), (1.0, 1.0));
        assert_eq!((at(0, 1).wall_s, at(0, 1).cpu_s), (2.0, 0.5));
        assert_eq!(at(1, 0).wall_s, 3.0);
        assert_eq!(at(1, 1).wall_s, 1.0);
    }

    #[test]
    fn fake_contention_gives_foreign_time_in_proportion_to_the_wall_time() {
        let t = Timing::new(Some("2"), Some("0,0.5")).unwrap();
        let quiet = t.trial(MEASURED, 0, 4);
        assert_eq!(quiet.elapsed.foreign.unwrap().cpu_s, 0.0);
        let busy = t.trial(MEASURED, 1, 4);
        // Half of 4 threads for 2 s.
        assert_eq!(busy.elapsed.foreign.unwrap().cpu_s, 4.0);
        assert_eq!(busy.load1, Some(2.0));
        assert_eq!(t.fake_busy_threads(4), Some(0.0));
    }

    #[test]
    fn every_run_of_a_sweep_has_its_own_fake_index() {
        use crate::results::rows::Phase;
        let (cells, trials, confirm) = (4, 3, 2);
        let mut seen = std::collections::HashSet::new();
        for c in 0..cells {
            for r in 1..=trials {
                assert!(seen.insert(fake_index(Phase::Grid, c, r, cells, trials, confirm)));
            }
            for r in 1..=confirm {
                assert!(seen.insert(fake_index(Phase::Confirm, c, r, cells, trials, confirm)));
            }
        }
        assert_eq!(seen.len(), cells * (trials + confirm));
        assert_eq!(seen.iter().max(), Some(&(cells * (trials + confirm) - 1)));
    }

    #[test]
    fn malformed_fake_lists_are_refused() {
        for bad in ["", "x", "1,,2", "0", "-1", "1:-1", "inf", "1:2:3"] {
            assert!(Timing::new(Some(bad), None).is_err(), "{bad}");
        }
        for bad in ["", "-0.1", "1.5", "x", "nan"] {
            assert!(Timing::new(None, Some(bad)).is_err(), "{bad}");
        }
    }
}
