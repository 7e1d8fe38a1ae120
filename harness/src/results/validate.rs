//! Whether a cell read back from a results directory can be believed: every number finite and
//! in range, and the summary row's statistics those of its trial rows.
//!
//! `sweep --resume` runs a kept cell through [`cell`] and runs it again when it fails;
//! `bench-sph report` drops such a cell with a listed warning. A hand-edited or corrupted row
//! must never become a number in a chart.

use super::rows::{Status, SummaryRow, TrialRow};
use super::stats::{Stats, mean};
use crate::limits;

/// Relative tolerance between a summary statistic and the same statistic recomputed from the
/// trial rows (the CSV holds shortest round-trip floats, so they agree exactly; the slack is
/// for files written by other tools).
const TOLERANCE: f64 = 1e-9;

/// Why the cell cannot be believed, or `Ok`.
// Over ~60 lines on purpose: one flat list of independent checks, each with its own message, read
// top to bottom.
pub fn cell(summary: &SummaryRow, trials: &[TrialRow]) -> Result<(), String> {
    summary_alone(summary)?;
    if trials.len() != summary.trials {
        return Err(format!(
            "the summary counts {} trials but trials.csv holds {}",
            summary.trials,
            trials.len()
        ));
    }
    numbering(trials)?;
    for t in trials {
        run(t)?;
        if summary.status == Status::Ok && t.status != Status::Ok {
            return Err(format!(
                "trial {} is marked {} ({}) in a cell marked ok",
                t.trial,
                t.status.as_str(),
                reason_or_dash(&t.reason)
            ));
        }
        if summary.status == Status::Ok && t.checksum != summary.checksum {
            return Err(format!(
                "trial {}: checksum {} differs from the cell's {}",
                t.trial, t.checksum, summary.checksum
            ));
        }
    }
    if summary.status == Status::Failed {
        return Ok(());
    }
    let walls: Vec<f64> = trials.iter().map(|t| t.wall_s).collect();
    let cpus: Vec<f64> = trials.iter().map(|t| t.cpu_s).collect();
    let Some(stats) = Stats::of(&walls) else {
        return Err("an ok cell without trials".to_owned());
    };
    let expected = [
        ("mean_s", summary.mean_s, Some(stats.mean)),
        ("min_s", summary.min_s, Some(stats.min)),
        ("median_s", summary.median_s, Some(stats.median)),
        ("max_s", summary.max_s, Some(stats.max)),
        ("stddev_s", summary.stddev_s, stats.stddev),
        ("cpu_mean_s", summary.cpu_mean_s, Some(mean(&cpus))),
    ];
    for (name, found, want) in expected {
        if !agrees(found, want) {
            return Err(format!(
                "{name} = {} disagrees with its trial rows ({})",
                show(found),
                show(want)
            ));
        }
    }
    Ok(())
}

/// Why a cell's trial rows (sorted by trial number) are not numbered as a sweep numbers them,
/// or `Ok`: trials 1, 2, … in order, and, where the rows have rounds (every sweep since
/// rounds), each in a later round than the one before, from round 1.
pub fn numbering(trials: &[TrialRow]) -> Result<(), String> {
    if trials.iter().enumerate().any(|(i, t)| t.trial != i + 1) {
        let numbers: Vec<String> = trials.iter().map(|t| t.trial.to_string()).collect();
        return Err(format!(
            "its trials are numbered {}, not 1 to {} (renumbered, repeated or missing rows)",
            numbers.join(", "),
            trials.len()
        ));
    }
    let with_rounds = trials.iter().filter(|t| t.round.is_some()).count();
    if with_rounds != 0 && with_rounds != trials.len() {
        return Err("some of its trials have a round and others none".to_owned());
    }
    let mut before = 0;
    for t in trials {
        match (t.round, t.position) {
            (None, _) => {}
            (Some(r), Some(p)) if r > before && p >= 1 => before = r,
            (Some(r), Some(p)) if r > before => {
                return Err(format!(
                    "trial {}: position {p} in round {r} (places in a round count from 1)",
                    t.trial
                ));
            }
            (Some(r), Some(_)) => {
                return Err(format!(
                    "trial {}: round {r} does not come after the round of trial {} ({before})",
                    t.trial,
                    t.trial - 1
                ));
            }
            (Some(r), None) => {
                return Err(format!(
                    "trial {}: round {r} without a position in it",
                    t.trial
                ));
            }
        }
    }
    Ok(())
}

/// Why one trial row's own numbers cannot be believed, or `Ok`: times finite and positive,
/// the machine's readings finite and non-negative.
pub fn run(t: &TrialRow) -> Result<(), String> {
    if !(t.wall_s.is_finite() && t.wall_s > 0.0) {
        return Err(format!(
            "trial {}: wall_s = {} is not a positive time",
            t.trial, t.wall_s
        ));
    }
    if !(t.cpu_s.is_finite() && t.cpu_s >= 0.0) {
        return Err(format!(
            "trial {}: cpu_s = {} is not a time",
            t.trial, t.cpu_s
        ));
    }
    for (name, value) in [
        ("foreign_cpu_s", t.foreign_cpu_s),
        ("steal_s", t.steal_s),
        ("load1", t.load1),
        ("window_foreign_threads", t.window_foreign_threads),
    ] {
        if let Some(v) = value
            && !(v.is_finite() && v >= 0.0)
        {
            return Err(format!(
                "trial {}: {name} = {v} is not a non-negative number",
                t.trial
            ));
        }
    }
    Ok(())
}

/// The checks that need no trial rows: ranges, finite positive statistics, a consistent
/// efficiency and interval.
// Over ~60 lines on purpose: one flat list of independent checks, each with its own message, read
// top to bottom.
pub fn summary_alone(row: &SummaryRow) -> Result<(), String> {
    limits::check("cores", row.cores, 1, limits::MAX_CORES).map_err(|e| e.to_string())?;
    limits::check("n", row.n, 1, limits::MAX_PARTICLES).map_err(|e| e.to_string())?;
    limits::check("steps", row.steps, 1, limits::MAX_STEPS).map_err(|e| e.to_string())?;
    // A failed cell may have stopped before its first trial (a warm-up failed, or its group
    // had no reference): 0 trials is then a result, not a broken row.
    let fewest = usize::from(row.status == Status::Ok);
    limits::check("trials", row.trials, fewest, limits::MAX_TRIALS).map_err(|e| e.to_string())?;
    if let Some(k) = row.chunks {
        limits::check("chunks", k, 1, limits::MAX_CHUNKS).map_err(|e| e.to_string())?;
    }
    if row.status == Status::Failed {
        return Ok(());
    }
    let positive = [
        ("mean_s", row.mean_s),
        ("min_s", row.min_s),
        ("median_s", row.median_s),
        ("max_s", row.max_s),
        ("speedup", row.speedup),
        ("efficiency", row.efficiency),
        ("mean_ci_low_s", row.mean_ci_low_s),
        ("mean_ci_high_s", row.mean_ci_high_s),
        ("speedup_ci_low", row.speedup_ci_low),
        ("speedup_ci_high", row.speedup_ci_high),
    ];
    for (name, value) in positive {
        if let Some(v) = value
            && !(v.is_finite() && v > 0.0)
        {
            return Err(format!("{name} = {v} is not a finite positive number"));
        }
    }
    let non_negative = [
        ("stddev_s", row.stddev_s),
        ("cpu_mean_s", row.cpu_mean_s),
        ("foreign_cpu_mean_s", row.foreign_cpu_mean_s),
    ];
    for (name, value) in non_negative {
        if let Some(v) = value
            && !(v.is_finite() && v >= 0.0)
        {
            return Err(format!("{name} = {v} is not a finite non-negative number"));
        }
    }
    let (Some(min), Some(mean), Some(max)) = (row.min_s, row.mean_s, row.max_s) else {
        return Err("an ok cell without mean_s, min_s and max_s".to_owned());
    };
    if !(min <= mean && mean <= max) {
        return Err(format!(
            "mean_s = {mean} lies outside min_s..max_s = {min}..{max}"
        ));
    }
    if let (Some(s), Some(e)) = (row.speedup, row.efficiency)
        && !close(e, s / row.cores as f64)
    {
        return Err(format!("efficiency = {e} is not speedup / cores"));
    }
    if let (Some(low), Some(high)) = (row.mean_ci_low_s, row.mean_ci_high_s)
        && low > high
    {
        return Err(format!("the interval {low}..{high} of mean_s is reversed"));
    }
    if let (Some(low), Some(high)) = (row.speedup_ci_low, row.speedup_ci_high)
        && low > high
    {
        return Err(format!("the interval {low}..{high} of speedup is reversed"));
    }
    Ok(())
}

fn agrees(found: Option<f64>, want: Option<f64>) -> bool {
    match (found, want) {
        (None, None) => true,
        (Some(a), Some(b)) => close(a, b),
        _ => false,
    }
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= TOLERANCE * a.abs().max(b.abs())
}

/// A row's `reason`, or a dash where it gives none.
pub fn reason_or_dash(reason: &str) -> &str {
    if reason.trim().is_empty() {
        "—"
    } else {
        reason
    }
}

/// Why a line of a results CSV (whose header is `columns`) is not a row: it has too few or too
/// many fields, or which column holds what cannot be read (e.g. `status` holds a word other
/// than `ok` and `failed`).
pub fn unreadable(err: &csv::Error, columns: &[&str]) -> String {
    match err.kind() {
        csv::ErrorKind::UnequalLengths {
            expected_len, len, ..
        } => format!("it has {len} fields, not {expected_len}"),
        csv::ErrorKind::Deserialize { err, .. } => {
            let column = err
                .field()
                .and_then(|i| usize::try_from(i).ok())
                .and_then(|i| columns.get(i));
            let what = match err.kind() {
                csv::DeserializeErrorKind::Message(m) => m.clone(),
                csv::DeserializeErrorKind::Unsupported(m) => m.clone(),
                csv::DeserializeErrorKind::UnexpectedEndOfRow => "a field is missing".to_owned(),
                csv::DeserializeErrorKind::InvalidUtf8(_) => "not UTF-8 text".to_owned(),
                csv::DeserializeErrorKind::ParseBool(_) => "not true or false".to_owned(),
                csv::DeserializeErrorKind::ParseInt(_) => "not a whole number".to_owned(),
                csv::DeserializeErrorKind::ParseFloat(_) => "not a number".to_owned(),
            };
            match column {
                Some(c) => format!("column {c}: {what}"),
                None => what,
            }
        }
        csv::ErrorKind::Utf8 { .. } => "not UTF-8 text".to_owned(),
        _ => "cut off, or garbled".to_owned(),
    }
}

fn show(v: Option<f64>) -> String {
    v.map_or_else(|| "empty".to_owned(), |v| v.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::results::key::Cell;
    use crate::results::key::test_group;
    use sph_solver::sph::neighbors::NeighborMode;
    use sph_strategies::StrategyName;

    fn rows() -> (SummaryRow, Vec<TrialRow>) {
        use crate::results::fixtures;
        use crate::results::rows::Phase;
        use crate::results::summarize::{CellContext, summary_row};
        let cell = Cell {
            group: test_group(NeighborMode::AllPairs),
            strategy: StrategyName::RayonChunks,
            cores: 2,
            chunks: Some(4),
            pin: crate::topology::Pin::None,
        };
        let trials = fixtures::trials(&cell, &[0.5, 0.6, 0.7]);
        let seq = fixtures::trials(&Cell::reference(cell.group), &[1.0, 1.1, 1.2]);
        let ctx = CellContext {
            hardware_threads: 2,
            shard: None,
            smt: None,
        };
        (
            summary_row(&cell, Phase::Grid, &trials, Some(&seq), None, &ctx),
            trials,
        )
    }

    #[test]
    fn a_cell_as_the_sweep_writes_it_passes() {
        let (s, t) = rows();
        assert_eq!(cell(&s, &t), Ok(()));
    }

    #[test]
    fn a_nan_or_negative_trial_time_is_refused() {
        let (s, mut t) = rows();
        t[1].wall_s = f64::NAN;
        assert!(cell(&s, &t).unwrap_err().contains("wall_s = NaN"));
        let (s, mut t) = rows();
        t[0].cpu_s = -5.0;
        assert!(cell(&s, &t).unwrap_err().contains("cpu_s = -5"));
    }

    #[test]
    fn a_summary_that_disagrees_with_its_trials_is_refused() {
        let (mut s, t) = rows();
        s.mean_s = Some(0.4);
        assert!(cell(&s, &t).unwrap_err().contains("mean_s = 0.4"));
        let (s, t) = rows();
        assert!(cell(&s, &t[..2]).unwrap_err().contains("counts 3 trials"));
    }

    #[test]
    fn a_failed_trial_in_an_ok_cell_and_renumbered_trials_or_rounds_are_refused() {
        let (s, mut t) = rows();
        t[1].status = Status::Failed;
        t[1].reason = "boom".to_owned();
        assert_eq!(
            cell(&s, &t).unwrap_err(),
            "trial 2 is marked failed (boom) in a cell marked ok"
        );
        let (s, mut t) = rows();
        t[2].trial = 7;
        assert!(
            cell(&s, &t)
                .unwrap_err()
                .contains("numbered 1, 2, 7, not 1 to 3"),
            "{t:?}"
        );
        let (s, mut t) = rows();
        t[2].round = Some(2);
        assert!(
            cell(&s, &t)
                .unwrap_err()
                .contains("trial 3: round 2 does not come after the round of trial 2 (2)")
        );
        let (s, mut t) = rows();
        t[0].round = None;
        assert!(
            cell(&s, &t)
                .unwrap_err()
                .contains("a round and others none")
        );
    }

    #[test]
    fn impossible_summary_numbers_are_refused_without_trials() {
        for edit in [
            (|s: &mut SummaryRow| s.mean_s = Some(-0.5)) as fn(&mut SummaryRow),
            |s| s.speedup = Some(f64::INFINITY),
            |s| s.cores = 1_000_000_000,
            |s| s.min_s = Some(0.0),
            |s| s.efficiency = Some(0.9),
        ] {
            let (mut s, _) = rows();
            edit(&mut s);
            assert!(summary_alone(&s).is_err(), "{s:?}");
        }
    }
}
