//! A cell's summary row as a pure function of its trial rows and its group's `seq` trial rows
//! of the same phase: what the sweep writes, and what a reader can recompute.
//!
//! - the statistics of the wall seconds ([`Stats`]) and the interval of the typical time
//!   ([`intervals::mean_interval`]);
//! - the speedup: the geometric mean of the per-round ratios `seq` / cell, with its interval
//!   ([`intervals::paired_ratio`]); efficiency = speedup / cores;
//! - `contended`: some run's contention window was contended (unknown when a run's verdict
//!   is unknown and none was contended).
//!
//! A failed cell's summary carries no statistic, speedup or efficiency: a bug must never
//! become a number.

use super::intervals::{self, Ratio};
use super::key::Cell;
use super::rows::{Phase, Status, SummaryRow, TrialRow};
use super::stats::{Stats, mean};

/// What a summary row records besides its trials.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CellContext {
    /// The machine's hardware threads (for `oversubscribed`).
    pub hardware_threads: usize,
    /// The shard this sweep is (its `reference_shard`), if it is one.
    pub shard: Option<usize>,
    /// Whether the cell's threads use SMT siblings ([`crate::topology::Topology::is_smt`]).
    pub smt: Option<bool>,
}

/// (round, wall seconds) of the ok runs among `trials`; runs without a round (files written
/// before rounds) are numbered by their trial number.
pub fn by_round(trials: &[TrialRow]) -> Vec<(usize, f64)> {
    trials
        .iter()
        .filter(|t| t.status == Status::Ok)
        .map(|t| (t.round.unwrap_or(t.trial), t.wall_s))
        .collect()
}

/// The speedup of `trials` over `seq` (both one phase of one group and shard): paired by
/// round.
pub fn speedup(seq: &[TrialRow], trials: &[TrialRow]) -> Option<Ratio> {
    intervals::paired_ratio(&by_round(seq), &by_round(trials))
}

/// How much slower the first run of a round is than the same cell's other runs: the
/// geometric mean, over every ok run at position 1, of its time over the geometric mean of
/// its cell's runs (same phase) at other positions, with its interval. A warm-up that falls
/// short shows as a ratio above 1 whose interval excludes 1. `None` without such runs.
pub fn first_run_effect(trials: &[TrialRow]) -> Option<Ratio> {
    let ok: Vec<&TrialRow> = trials
        .iter()
        .filter(|t| t.status == Status::Ok && t.position.is_some())
        .collect();
    let ratios: Vec<f64> = ok
        .iter()
        .filter(|t| t.position == Some(1))
        .filter_map(|first| {
            let others: Vec<f64> = ok
                .iter()
                .filter(|t| t.phased_key() == first.phased_key() && t.position != Some(1))
                .map(|t| t.wall_s.ln())
                .collect();
            (!others.is_empty()).then(|| first.wall_s / mean(&others).exp())
        })
        .collect();
    intervals::ratio(&ratios)
}

/// The summary row of `cell` in `phase` from its trial rows, against the group's `seq` trial
/// rows of the phase (`None`: no reference, so no speedup); `failure` says why the cell
/// failed, if it did.
// Over ~60 lines on purpose: most of it is one struct literal, every column of summary.csv in
// order.
pub fn summary_row(
    cell: &Cell,
    phase: Phase,
    trials: &[TrialRow],
    seq: Option<&[TrialRow]>,
    failure: Option<&str>,
    ctx: &CellContext,
) -> SummaryRow {
    let walls: Vec<f64> = trials.iter().map(|t| t.wall_s).collect();
    let cpus: Vec<f64> = trials.iter().map(|t| t.cpu_s).collect();
    let stats = Stats::of(&walls).filter(|_| failure.is_none());
    let mean_ci = stats.and_then(|_| intervals::mean_interval(&walls));
    let ratio = stats.and_then(|_| speedup(seq?, trials));
    let foreign: Option<Vec<f64>> = trials.iter().map(|t| t.foreign_cpu_s).collect();
    let foreign = foreign.filter(|f| !f.is_empty());
    let contended = if trials.iter().any(|t| t.contended == Some(true)) {
        Some(true)
    } else if !trials.is_empty() && trials.iter().all(|t| t.contended == Some(false)) {
        Some(false)
    } else {
        None
    };
    let speedup = ratio.map(|r| r.value);
    SummaryRow {
        strategy: cell.strategy,
        neighbors: cell.group.neighbors,
        preset: cell.group.preset,
        n: cell.group.n,
        steps: cell.group.steps,
        cores: cell.cores,
        chunks: cell.chunks,
        particles_per_chunk: cell.particles_per_chunk(),
        trials: trials.len(),
        mean_s: stats.map(|s| s.mean),
        stddev_s: stats.and_then(|s| s.stddev),
        min_s: stats.map(|s| s.min),
        median_s: stats.map(|s| s.median),
        max_s: stats.map(|s| s.max),
        cpu_mean_s: stats.map(|_| mean(&cpus)),
        speedup,
        efficiency: speedup.map(|s| s / cell.cores as f64),
        outliers: stats.map(|s| s.outliers),
        oversubscribed: cell.oversubscribed(ctx.hardware_threads),
        checksum: match (failure, trials.first()) {
            (None, Some(t)) => t.checksum.clone(),
            _ => String::new(),
        },
        status: if failure.is_some() {
            Status::Failed
        } else {
            Status::Ok
        },
        reason: failure.unwrap_or_default().to_owned(),
        mean_ci_low_s: mean_ci.map(|i| i.low),
        mean_ci_high_s: mean_ci.map(|i| i.high),
        speedup_ci_low: ratio.and_then(|r| r.interval).map(|i| i.low),
        speedup_ci_high: ratio.and_then(|r| r.interval).map(|i| i.high),
        foreign_cpu_mean_s: foreign.as_deref().map(mean),
        contended,
        reference_shard: ctx.shard,
        pin: cell.pin,
        smt: ctx.smt,
        phase,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::results::fixtures::trials;
    use crate::results::key::test_group;
    use sph_solver::sph::neighbors::NeighborMode;
    use sph_strategies::StrategyName;

    fn cell(strategy: StrategyName, cores: usize, chunks: Option<usize>) -> Cell {
        Cell {
            group: test_group(NeighborMode::AllPairs),
            strategy,
            cores,
            chunks,
            pin: crate::topology::Pin::None,
        }
    }

    const CTX: CellContext = CellContext {
        hardware_threads: 1,
        shard: None,
        smt: None,
    };

    #[test]
    fn a_summary_carries_the_statistics_and_the_paired_speedup() {
        let c = cell(StrategyName::RayonChunks, 2, Some(7));
        let seq = trials(&Cell::reference(c.group), &[4.0, 8.0, 6.0]);
        let t = trials(&c, &[2.0, 4.0, 3.0]);
        let row = summary_row(&c, Phase::Grid, &t, Some(&seq), None, &CTX);
        assert_eq!(row.trials, 3);
        assert_eq!(row.mean_s, Some(3.0));
        assert_eq!(row.stddev_s, Some(1.0));
        assert_eq!(
            (row.min_s, row.median_s, row.max_s),
            (Some(2.0), Some(3.0), Some(4.0))
        );
        assert_eq!(row.cpu_mean_s, Some(6.0));
        // Every round's seq took twice the cell's time, though both drifted from round to
        // round: the paired speedup is exactly 2, its interval a point.
        assert!((row.speedup.unwrap() - 2.0).abs() < 1e-12);
        assert!((row.efficiency.unwrap() - 1.0).abs() < 1e-12);
        assert!((row.speedup_ci_low.unwrap() - 2.0).abs() < 1e-12);
        assert!((row.speedup_ci_high.unwrap() - 2.0).abs() < 1e-12);
        assert_eq!(
            (row.mean_ci_low_s, row.mean_ci_high_s),
            intervals::mean_interval(&[2.0, 4.0, 3.0])
                .map(|i| (Some(i.low), Some(i.high)))
                .unwrap()
        );
        assert_eq!(row.outliers, Some(0));
        assert_eq!(row.particles_per_chunk, Some(9));
        assert!(row.oversubscribed);
        assert_eq!((row.status, row.reason.as_str()), (Status::Ok, ""));
        assert_eq!(row.checksum, "00000000000000aa");
        assert_eq!(row.foreign_cpu_mean_s, Some(0.03));
        assert_eq!(row.contended, Some(false));
        assert_eq!(row.phase, Phase::Grid);
    }

    #[test]
    fn a_first_run_of_each_round_slower_than_the_rest_shows_and_an_even_one_does_not() {
        // Four cells, five rounds; each round's first run is cell (round mod 4), with a fixed
        // ±2 % noise.
        let rounds_of = |slow: f64| -> Vec<TrialRow> {
            let mut all = Vec::new();
            for c in 0..4usize {
                let cell = cell(StrategyName::RayonChunks, 1, Some(c + 1));
                let mut t = trials(&cell, &[1.0; 5]);
                for (r, run) in t.iter_mut().enumerate() {
                    let first = (r + 1) % 4 == c;
                    run.position = Some(if first { 1 } else { 2 + (c + r) % 3 });
                    let noise = [1.02, 0.98, 1.0, 1.01, 0.99][r];
                    run.wall_s = if first { noise * slow } else { 1.0 };
                }
                all.extend(t);
            }
            all
        };
        let slow = first_run_effect(&rounds_of(1.1)).unwrap();
        assert!(
            slow.resolved() && (slow.value - 1.1).abs() < 0.03,
            "{slow:?}"
        );
        let even = first_run_effect(&rounds_of(1.0)).unwrap();
        assert!(!even.resolved(), "{even:?}");
        assert_eq!(first_run_effect(&[]), None);
    }

    #[test]
    fn one_contended_run_makes_the_cell_contended_and_an_unknown_one_unknown() {
        let c = cell(StrategyName::RayonChunks, 2, Some(7));
        let mut t = trials(&c, &[1.0, 1.0, 1.0]);
        t[2].contended = None;
        assert_eq!(
            summary_row(&c, Phase::Grid, &t, None, None, &CTX).contended,
            None
        );
        t[1].contended = Some(true);
        assert_eq!(
            summary_row(&c, Phase::Grid, &t, None, None, &CTX).contended,
            Some(true)
        );
    }

    #[test]
    fn fewer_than_three_rounds_give_numbers_without_intervals() {
        let c = cell(StrategyName::RayonIter, 2, None);
        let seq = trials(&Cell::reference(c.group), &[4.0, 4.0]);
        let row = summary_row(
            &c,
            Phase::Grid,
            &trials(&c, &[1.0, 2.0]),
            Some(&seq),
            None,
            &CTX,
        );
        assert!(row.speedup.is_some() && row.mean_s == Some(1.5));
        assert_eq!((row.speedup_ci_low, row.mean_ci_low_s), (None, None));
    }

    #[test]
    fn rounds_without_a_seq_partner_are_left_out_of_the_speedup() {
        let c = cell(StrategyName::RayonIter, 2, None);
        let seq = trials(&Cell::reference(c.group), &[4.0, 4.0, 4.0]);
        let mut t = trials(&c, &[2.0, 2.0, 2.0, 1.0]);
        t[3].round = Some(9);
        let row = summary_row(&c, Phase::Grid, &t, Some(&seq), None, &CTX);
        assert_eq!(row.speedup, Some(2.0));
    }

    #[test]
    fn a_failed_cell_has_a_reason_and_no_numbers() {
        let c = cell(StrategyName::RayonIter, 2, None);
        let t = trials(&c, &[1.0, 2.0]);
        let seq = trials(&Cell::reference(c.group), &[4.0]);
        let row = summary_row(
            &c,
            Phase::Confirm,
            &t,
            Some(&seq),
            Some("checksum differs"),
            &CTX,
        );
        assert_eq!(row.status, Status::Failed);
        assert_eq!(row.reason, "checksum differs");
        assert_eq!(row.trials, 2);
        assert!(row.mean_s.is_none() && row.median_s.is_none() && row.cpu_mean_s.is_none());
        assert!(row.speedup.is_none() && row.efficiency.is_none() && row.outliers.is_none());
        assert!(row.checksum.is_empty());
        assert!(row.mean_ci_low_s.is_none() && row.speedup_ci_high.is_none());
        assert_eq!(row.phase, Phase::Confirm);
    }
}
