//! The rows of `trials.csv` and `summary.csv`, and how a cell's measurements become them.
//!
//! Field names are the column names. Times are seconds; an empty field means "not defined"
//! (chunks of a strategy without chunks, the stddev of one trial, any statistic of a failed
//! cell). `status` is `ok` or `failed`; a failed cell's `reason` says why, and its summary
//! carries no statistic, speedup or efficiency: a bug must never become a number.

use serde::{Deserialize, Serialize};

use super::plan::{Cell, CellKey};
use super::stats::{Stats, mean};
use crate::clock::Elapsed;

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
    /// Wall and CPU seconds of the step loop.
    pub elapsed: Elapsed,
    /// [`crate::checksum::checksum_hex`] of the final state.
    pub checksum: String,
}

/// One row of `trials.csv`: one timed run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TrialRow {
    /// Strategy name.
    pub strategy: String,
    /// Neighbour search.
    pub neighbors: String,
    /// Preset.
    pub preset: String,
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
}

/// One row of `summary.csv`: one cell.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SummaryRow {
    /// Strategy name.
    pub strategy: String,
    /// Neighbour search.
    pub neighbors: String,
    /// Preset.
    pub preset: String,
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
}

impl TrialRow {
    /// The row's cell.
    pub fn key(&self) -> CellKey {
        CellKey {
            strategy: self.strategy.clone(),
            neighbors: self.neighbors.clone(),
            preset: self.preset.clone(),
            n: self.n,
            steps: self.steps,
            cores: self.cores,
            chunks: self.chunks,
        }
    }
}

impl SummaryRow {
    /// The row's cell.
    pub fn key(&self) -> CellKey {
        CellKey {
            strategy: self.strategy.clone(),
            neighbors: self.neighbors.clone(),
            preset: self.preset.clone(),
            n: self.n,
            steps: self.steps,
            cores: self.cores,
            chunks: self.chunks,
        }
    }
}

/// The trial rows of a cell: one per measured run, all with the cell's status and reason.
pub fn trial_rows(cell: &Cell, measured: &[Measured], failure: Option<&str>) -> Vec<TrialRow> {
    let key = cell.key();
    measured
        .iter()
        .enumerate()
        .map(|(i, m)| TrialRow {
            strategy: key.strategy.clone(),
            neighbors: key.neighbors.clone(),
            preset: key.preset.clone(),
            n: key.n,
            steps: key.steps,
            cores: key.cores,
            chunks: key.chunks,
            particles_per_chunk: cell.particles_per_chunk(),
            trial: i + 1,
            wall_s: m.elapsed.wall_s,
            cpu_s: m.elapsed.cpu_s,
            checksum: m.checksum.clone(),
            status: status_of(failure),
            reason: failure.unwrap_or_default().to_owned(),
        })
        .collect()
}

/// The summary row of a cell. `seq_mean_s` is the group's reference mean (for the reference
/// cell itself, its own mean); without it, or for a failed cell, there is no speedup.
pub fn summary_row(
    cell: &Cell,
    measured: &[Measured],
    failure: Option<&str>,
    seq_mean_s: Option<f64>,
    hardware_threads: usize,
) -> SummaryRow {
    let key = cell.key();
    let walls: Vec<f64> = measured.iter().map(|m| m.elapsed.wall_s).collect();
    let cpus: Vec<f64> = measured.iter().map(|m| m.elapsed.cpu_s).collect();
    let stats = Stats::of(&walls).filter(|_| failure.is_none());
    let speedup = stats.and_then(|s| seq_mean_s.map(|seq| seq / s.mean));
    SummaryRow {
        strategy: key.strategy,
        neighbors: key.neighbors,
        preset: key.preset,
        n: key.n,
        steps: key.steps,
        cores: key.cores,
        chunks: key.chunks,
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
        oversubscribed: cell.oversubscribed(hardware_threads),
        checksum: match (failure, measured.first()) {
            (None, Some(m)) => m.checksum.clone(),
            _ => String::new(),
        },
        status: status_of(failure),
        reason: failure.unwrap_or_default().to_owned(),
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
    use crate::sph::neighbors::NeighborMode;
    use crate::sph::params::Preset;
    use crate::sweep::plan::Group;
    use sph_strategies::StrategyName;

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
                },
                checksum: "00000000000000aa".to_owned(),
            })
            .collect()
    }

    #[test]
    fn a_summary_carries_the_statistics_speedup_and_efficiency() {
        let c = cell(StrategyName::RayonChunks, 2, Some(7));
        let row = summary_row(&c, &measured(&[1.0, 2.0, 3.0]), None, Some(4.0), 1);
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
    }

    #[test]
    fn a_failed_cell_has_a_reason_and_no_numbers() {
        let c = cell(StrategyName::RayonIter, 2, None);
        let m = measured(&[1.0, 2.0]);
        let row = summary_row(&c, &m, Some("checksum differs"), Some(4.0), 2);
        assert_eq!(row.status, Status::Failed);
        assert_eq!(row.reason, "checksum differs");
        assert_eq!(row.trials, 2);
        assert!(row.mean_s.is_none() && row.median_s.is_none() && row.cpu_mean_s.is_none());
        assert!(row.speedup.is_none() && row.efficiency.is_none() && row.outliers.is_none());
        assert!(row.checksum.is_empty() && !row.oversubscribed);
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
        assert_eq!(rows[1].key(), c.key());
        assert_eq!(rows[1].particles_per_chunk, Some(12));
        assert_eq!(rows[0].status, Status::Ok);
    }
}
