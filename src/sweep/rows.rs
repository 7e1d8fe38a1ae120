//! The rows of `trials.csv` and `summary.csv`, and how a cell's measurements become them.
//!
//! Field names are the column names. Times are seconds; an empty field means "not defined"
//! (chunks of a strategy without chunks, the stddev of one trial, any statistic of a failed
//! cell, anything unmeasurable on this OS). `status` is `ok` or `failed`; a failed cell's
//! `reason` says why, and its summary carries no statistic, speedup or efficiency: a bug must
//! never become a number.
//!
//! Columns added after the first release are appended at the end of each row (older readers
//! keep working): per trial `foreign_cpu_s, steal_s, load1` ([`crate::contention`]); per cell
//! the 95 % bootstrap intervals `mean_ci_low_s, mean_ci_high_s, speedup_ci_low,
//! speedup_ci_high` ([`super::bootstrap`]), `foreign_cpu_mean_s` and `contended` (some trial
//! saw more foreign CPU than [`Threshold::allowed_s`]).

use serde::{Deserialize, Serialize};

use super::bootstrap::{self, Interval};
use super::plan::{Cell, Group};
use super::stats::{Stats, mean};
use crate::clock::Elapsed;
use crate::contention::Threshold;
use crate::sph::neighbors::NeighborMode;
use crate::sph::params::Preset;
use sph_strategies::StrategyName;

/// Whether a cell's numbers can be used.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Status {
    /// Every run finished and reproduced the group's `seq` checksum.
    Ok,
    /// A run failed or its checksum differed: see `reason`.
    Failed,
}

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

/// One row of `trials.csv`: one timed run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TrialRow {
    /// Strategy.
    #[serde(with = "super::params::name")]
    pub strategy: StrategyName,
    /// Neighbour search.
    #[serde(with = "super::params::name")]
    pub neighbors: NeighborMode,
    /// Preset.
    #[serde(with = "super::params::name")]
    pub preset: Preset,
    /// Particles.
    pub n: usize,
    /// Steps.
    pub steps: usize,
    /// Worker threads.
    pub cores: usize,
    /// Requested chunks (empty for strategies without chunks).
    pub chunks: Option<usize>,
    /// Particles in the largest chunk (empty for strategies without chunks).
    pub particles_per_chunk: Option<usize>,
    /// Trial number, from 1.
    pub trial: usize,
    /// Wall-clock seconds of the step loop.
    pub wall_s: f64,
    /// Process CPU seconds (user + system) over the same window.
    pub cpu_s: f64,
    /// Checksum of the final state (16 hex digits).
    pub checksum: String,
    /// The cell's status.
    pub status: Status,
    /// Why the cell failed (empty when ok).
    pub reason: String,
    /// Busy CPU seconds of the machine not spent by this process over the same window.
    #[serde(default)]
    pub foreign_cpu_s: Option<f64>,
    /// Of those, seconds stolen by the hypervisor.
    #[serde(default)]
    pub steal_s: Option<f64>,
    /// The 1-minute load average when the trial started.
    #[serde(default)]
    pub load1: Option<f64>,
}

/// One row of `summary.csv`: one cell. Its first columns repeat [`TrialRow`]'s cell key on
/// purpose: the csv crate cannot write a nested (`flatten`ed) key struct as flat columns.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SummaryRow {
    /// Strategy.
    #[serde(with = "super::params::name")]
    pub strategy: StrategyName,
    /// Neighbour search.
    #[serde(with = "super::params::name")]
    pub neighbors: NeighborMode,
    /// Preset.
    #[serde(with = "super::params::name")]
    pub preset: Preset,
    /// Particles.
    pub n: usize,
    /// Steps.
    pub steps: usize,
    /// Worker threads.
    pub cores: usize,
    /// Requested chunks (empty for strategies without chunks).
    pub chunks: Option<usize>,
    /// Particles in the largest chunk (empty for strategies without chunks).
    pub particles_per_chunk: Option<usize>,
    /// Trials completed (the rows of this cell in `trials.csv`).
    pub trials: usize,
    /// Mean wall seconds.
    pub mean_s: Option<f64>,
    /// Sample standard deviation of the wall seconds (empty for one trial).
    pub stddev_s: Option<f64>,
    /// Fastest trial, wall seconds.
    pub min_s: Option<f64>,
    /// Median wall seconds.
    pub median_s: Option<f64>,
    /// Slowest trial, wall seconds.
    pub max_s: Option<f64>,
    /// Mean CPU seconds (user + system).
    pub cpu_mean_s: Option<f64>,
    /// The group's `seq` mean divided by this cell's mean.
    pub speedup: Option<f64>,
    /// Speedup divided by cores.
    pub efficiency: Option<f64>,
    /// Trials with |t − median| > 3 MAD.
    pub outliers: Option<usize>,
    /// Whether cores exceed the machine's hardware threads.
    pub oversubscribed: bool,
    /// The checksum every trial reproduced (empty for a failed cell).
    pub checksum: String,
    /// `ok` or `failed`.
    pub status: Status,
    /// Why the cell failed (empty when ok).
    pub reason: String,
    /// Lower end of the 95 % bootstrap interval of the mean wall seconds.
    #[serde(default)]
    pub mean_ci_low_s: Option<f64>,
    /// Upper end of that interval.
    #[serde(default)]
    pub mean_ci_high_s: Option<f64>,
    /// Lower end of the 95 % bootstrap interval of the speedup.
    #[serde(default)]
    pub speedup_ci_low: Option<f64>,
    /// Upper end of that interval.
    #[serde(default)]
    pub speedup_ci_high: Option<f64>,
    /// Mean foreign CPU seconds per trial.
    #[serde(default)]
    pub foreign_cpu_mean_s: Option<f64>,
    /// Whether some trial saw more foreign CPU than the threshold (empty where unknown).
    #[serde(default)]
    pub contended: Option<bool>,
}

/// The columns that name a row's cell, shared by both files.
macro_rules! keyed {
    ($row:ty) => {
        impl $row {
            /// The row's group.
            pub fn group(&self) -> Group {
                Group {
                    preset: self.preset,
                    neighbors: self.neighbors,
                    n: self.n,
                    steps: self.steps,
                }
            }

            /// The row's cell.
            pub fn key(&self) -> Cell {
                Cell {
                    group: self.group(),
                    strategy: self.strategy,
                    cores: self.cores,
                    chunks: self.chunks,
                }
            }
        }
    };
}
keyed!(TrialRow);
keyed!(SummaryRow);

impl TrialRow {
    /// Whether the row is a trial of its group's `seq` reference cell.
    pub fn is_reference(&self) -> bool {
        self.key().is_reference()
    }
}

impl SummaryRow {
    /// Whether the row is its group's `seq` reference cell.
    pub fn is_reference(&self) -> bool {
        self.key().is_reference()
    }

    /// Whether the row's numbers may be used: status ok, with a mean.
    pub fn is_usable(&self) -> bool {
        self.status == Status::Ok && self.mean_s.is_some()
    }
}

/// How [`fastest`] treats cells that other work disturbed (`contended = true`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Contended {
    /// They compete like any other cell (the sweep's end-of-run table, which shows what was
    /// measured).
    Compete,
    /// Only when every candidate is contended (the report, whose findings trust no
    /// contended cell).
    LastResort,
}

/// The one "best cell" rule: the usable row of `rows` with the lowest mean (the first of
/// equals), contended rows treated as `contended` says.
pub fn fastest<'a>(
    rows: impl IntoIterator<Item = &'a SummaryRow>,
    contended: Contended,
) -> Option<&'a SummaryRow> {
    let disturbed =
        |r: &SummaryRow| contended == Contended::LastResort && r.contended == Some(true);
    rows.into_iter().filter(|r| r.is_usable()).min_by(|a, b| {
        disturbed(a).cmp(&disturbed(b)).then(
            a.mean_s
                .unwrap_or(f64::INFINITY)
                .total_cmp(&b.mean_s.unwrap_or(f64::INFINITY)),
        )
    })
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
}

/// The summary row of a cell, against `ctx`; a failed cell has no statistics, speedup or
/// intervals.
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

    fn cell(strategy: StrategyName, cores: usize, chunks: Option<usize>) -> Cell {
        Cell {
            group: Group {
                preset: Preset::Seed,
                neighbors: NeighborMode::AllPairs,
                n: 60,
                steps: 3,
            },
            strategy,
            cores,
            chunks,
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
