//! How a cell's measurements become its rows of `trials.csv` and `summary.csv`
//! ([`crate::results::rows`]): the statistics, the speedup over the group's `seq`, the
//! bootstrap intervals ([`super::bootstrap`]) and the contention flag (some trial saw more
//! foreign CPU than [`Threshold::allowed_s`], or ran passes alone). A failed cell's summary
//! carries no statistic, speedup or efficiency: a bug must never become a number.

use super::bootstrap;
use crate::clock::Elapsed;
use crate::contention::Threshold;
use crate::results::key::Cell;
use crate::results::rows::{Status, SummaryRow, TrialRow};
use crate::results::stats::{Interval, Stats, mean};

/// One timed run: its times and the checksum of its final state.
#[derive(Debug, Clone, PartialEq)]
pub struct Measured {
    /// Wall, CPU and foreign CPU seconds of the step loop.
    pub elapsed: Elapsed,
    /// The 1-minute load average when the run started (`None` where unknown).
    pub load1: Option<f64>,
    /// [`crate::checksum::checksum_hex`] of the final state.
    pub checksum: String,
}

/// The trial rows of a cell: one per measured run, all with the cell's status and reason.
pub fn trial_rows(cell: &Cell, measured: &[Measured], failure: Option<&str>) -> Vec<TrialRow> {
    measured
        .iter()
        .enumerate()
        .map(|(i, m)| TrialRow {
            strategy: cell.strategy,
            neighbors: cell.group.neighbors,
            preset: cell.group.preset,
            n: cell.group.n,
            steps: cell.group.steps,
            cores: cell.cores,
            chunks: cell.chunks,
            particles_per_chunk: cell.particles_per_chunk(),
            trial: i + 1,
            wall_s: m.elapsed.wall_s,
            cpu_s: m.elapsed.cpu_s,
            checksum: m.checksum.clone(),
            status: status_of(failure),
            reason: failure.unwrap_or_default().to_owned(),
            foreign_cpu_s: m.elapsed.foreign.map(|f| f.cpu_s),
            steal_s: m.elapsed.foreign.and_then(|f| f.steal_s),
            load1: m.load1,
            pin: cell.pin,
            passes_alone: None,
        })
        .collect()
}

/// What a summary row is computed against.
#[derive(Debug, Clone, Copy)]
pub struct CellContext<'a> {
    /// The wall seconds of the group's `seq` trials (for the reference cell, its own); without
    /// them there is no speedup.
    pub seq_walls: Option<&'a [f64]>,
    /// The machine's hardware threads (for `oversubscribed`).
    pub hardware_threads: usize,
    /// When foreign CPU makes a trial contended.
    pub threshold: Threshold,
    /// The sweep's seed (the bootstrap's streams derive from it).
    pub seed: u64,
    /// Bootstrap resamples per interval.
    pub resamples: usize,
    /// The shard this sweep is (its `reference_shard`), if it is one.
    pub shard: Option<usize>,
    /// Whether the cell's threads use SMT siblings ([`crate::topology::Topology::is_smt`]).
    pub smt: Option<bool>,
}

/// The summary row of a cell, against `ctx`; a failed cell has no statistics, speedup or
/// intervals.
// Over ~60 lines on purpose: most of it is one struct literal, every column of summary.csv in
// order.
pub fn summary_row(
    cell: &Cell,
    measured: &[Measured],
    failure: Option<&str>,
    ctx: &CellContext<'_>,
) -> SummaryRow {
    let walls: Vec<f64> = measured.iter().map(|m| m.elapsed.wall_s).collect();
    let cpus: Vec<f64> = measured.iter().map(|m| m.elapsed.cpu_s).collect();
    let stats = Stats::of(&walls).filter(|_| failure.is_none());
    let seq_walls = ctx.seq_walls.filter(|w| !w.is_empty());
    let speedup = stats.and_then(|s| seq_walls.map(|seq| mean(seq) / s.mean));
    let label = cell.stream_key();
    let mean_ci = stats.and_then(|_| {
        bootstrap::mean_interval(
            &walls,
            ctx.resamples,
            &mut bootstrap::rng_for(ctx.seed, &label, 0),
        )
    });
    let speedup_ci = stats.and_then(|_| {
        let mut rng = bootstrap::rng_for(ctx.seed, &label, 1);
        bootstrap::ratio_interval(seq_walls?, &walls, ctx.resamples, &mut rng)
    });
    let foreign: Option<Vec<f64>> = measured
        .iter()
        .map(|m| m.elapsed.foreign.map(|f| f.cpu_s))
        .collect();
    let foreign = foreign.filter(|f| !f.is_empty());
    SummaryRow {
        strategy: cell.strategy,
        neighbors: cell.group.neighbors,
        preset: cell.group.preset,
        n: cell.group.n,
        steps: cell.group.steps,
        cores: cell.cores,
        chunks: cell.chunks,
        particles_per_chunk: cell.particles_per_chunk(),
        trials: measured.len(),
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
        checksum: match (failure, measured.first()) {
            (None, Some(m)) => m.checksum.clone(),
            _ => String::new(),
        },
        status: status_of(failure),
        reason: failure.unwrap_or_default().to_owned(),
        mean_ci_low_s: mean_ci.map(|i: Interval| i.low),
        mean_ci_high_s: mean_ci.map(|i| i.high),
        speedup_ci_low: speedup_ci.map(|i| i.low),
        speedup_ci_high: speedup_ci.map(|i| i.high),
        foreign_cpu_mean_s: foreign.as_deref().map(mean),
        contended: foreign.map(|f| {
            f.iter()
                .zip(&walls)
                .any(|(&foreign, &wall)| ctx.threshold.exceeded(foreign, wall, cell.cores))
        }),
        reference_shard: ctx.shard,
        pin: cell.pin,
        smt: ctx.smt,
    }
}

/// A context for tests: no foreign-CPU slack beyond the rule, seed 1, 1000 resamples.
#[cfg(test)]
pub(crate) fn test_context(seq_walls: Option<&[f64]>, hardware_threads: usize) -> CellContext<'_> {
    CellContext {
        seq_walls,
        hardware_threads,
        threshold: Threshold {
            hardware_threads,
            hz: 100.0,
        },
        seed: 1,
        resamples: 1000,
        shard: None,
        smt: None,
    }
}

fn status_of(failure: Option<&str>) -> Status {
    if failure.is_some() {
        Status::Failed
    } else {
        Status::Ok
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contention::Foreign;
    use crate::results::key::test_group;
    use crate::sph::neighbors::NeighborMode;
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

    fn measured(walls: &[f64]) -> Vec<Measured> {
        walls
            .iter()
            .map(|&w| Measured {
                elapsed: Elapsed {
                    wall_s: w,
                    cpu_s: 2.0 * w,
                    foreign: Some(Foreign {
                        cpu_s: 0.01 * w,
                        steal_s: Some(0.0),
                    }),
                },
                load1: Some(0.25),
                checksum: "00000000000000aa".to_owned(),
            })
            .collect()
    }

    #[test]
    fn a_summary_carries_the_statistics_speedup_and_efficiency() {
        let c = cell(StrategyName::RayonChunks, 2, Some(7));
        let row = summary_row(
            &c,
            &measured(&[1.0, 2.0, 3.0]),
            None,
            &test_context(Some(&[4.0, 4.0]), 1),
        );
        assert_eq!(row.trials, 3);
        assert_eq!(row.mean_s, Some(2.0));
        assert_eq!(row.stddev_s, Some(1.0));
        assert_eq!(
            (row.min_s, row.median_s, row.max_s),
            (Some(1.0), Some(2.0), Some(3.0))
        );
        assert_eq!(row.cpu_mean_s, Some(4.0));
        assert_eq!(row.speedup, Some(2.0));
        assert_eq!(row.efficiency, Some(1.0));
        assert_eq!(row.outliers, Some(0));
        assert_eq!(row.particles_per_chunk, Some(9));
        assert!(row.oversubscribed);
        assert_eq!((row.status, row.reason.as_str()), (Status::Ok, ""));
        assert_eq!(row.checksum, "00000000000000aa");
        let (lo, hi) = (row.mean_ci_low_s.unwrap(), row.mean_ci_high_s.unwrap());
        assert!(
            (1.0..2.0).contains(&lo) && hi > 2.0 && hi <= 3.0,
            "{lo} {hi}"
        );
        let (lo, hi) = (row.speedup_ci_low.unwrap(), row.speedup_ci_high.unwrap());
        assert!(
            (4.0 / 3.0..2.0).contains(&lo) && hi > 2.0 && hi <= 4.0,
            "{lo} {hi}"
        );
        assert_eq!(row.foreign_cpu_mean_s, Some(0.02));
        assert_eq!(row.contended, Some(false));
    }

    #[test]
    fn a_trial_with_too_much_foreign_cpu_makes_the_cell_contended() {
        let c = cell(StrategyName::RayonChunks, 2, Some(7));
        let mut m = measured(&[1.0, 1.0, 1.0]);
        // 2 threads: allowed 5 % × 2 × 1 s + 2 ticks × 2 = 0.14 s.
        m[1].elapsed.foreign = Some(Foreign {
            cpu_s: 0.15,
            steal_s: None,
        });
        let row = summary_row(&c, &m, None, &test_context(None, 2));
        assert_eq!(row.contended, Some(true));
        m[1].elapsed.foreign = Some(Foreign {
            cpu_s: 0.14,
            steal_s: None,
        });
        assert_eq!(
            summary_row(&c, &m, None, &test_context(None, 2)).contended,
            Some(false)
        );
    }

    #[test]
    fn without_foreign_readings_contention_is_unknown_not_invented() {
        let c = cell(StrategyName::Seq, 1, None);
        let mut m = measured(&[1.0, 1.0]);
        m[0].elapsed.foreign = None;
        let row = summary_row(&c, &m, None, &test_context(None, 2));
        assert_eq!((row.contended, row.foreign_cpu_mean_s), (None, None));
        let trials = trial_rows(&c, &m, None);
        assert_eq!((trials[0].foreign_cpu_s, trials[0].steal_s), (None, None));
        assert_eq!(trials[1].steal_s, Some(0.0));
    }

    #[test]
    fn a_failed_cell_has_a_reason_and_no_numbers() {
        let c = cell(StrategyName::RayonIter, 2, None);
        let m = measured(&[1.0, 2.0]);
        let row = summary_row(
            &c,
            &m,
            Some("checksum differs"),
            &test_context(Some(&[4.0]), 2),
        );
        assert_eq!(row.status, Status::Failed);
        assert_eq!(row.reason, "checksum differs");
        assert_eq!(row.trials, 2);
        assert!(row.mean_s.is_none() && row.median_s.is_none() && row.cpu_mean_s.is_none());
        assert!(row.speedup.is_none() && row.efficiency.is_none() && row.outliers.is_none());
        assert!(row.checksum.is_empty() && !row.oversubscribed);
        assert!(row.mean_ci_low_s.is_none() && row.speedup_ci_high.is_none());
        let trials = trial_rows(&c, &m, Some("checksum differs"));
        assert!(trials.iter().all(|t| t.status == Status::Failed));
        assert_eq!(trials[1].trial, 2);
        assert_eq!(trials[1].chunks, None);
    }

    #[test]
    fn trial_rows_number_the_trials_from_one_and_share_the_cell_key() {
        let c = cell(StrategyName::CrossbeamPool, 2, Some(5));
        let rows = trial_rows(&c, &measured(&[0.5, 0.25]), None);
        assert_eq!(rows.len(), 2);
        assert_eq!(
            (rows[0].trial, rows[0].wall_s, rows[0].cpu_s),
            (1, 0.5, 1.0)
        );
        assert_eq!(rows[1].key(), c);
        assert_eq!(rows[1].particles_per_chunk, Some(12));
        assert_eq!(rows[0].status, Status::Ok);
    }
}
