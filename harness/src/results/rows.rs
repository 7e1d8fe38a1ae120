//! The rows of `trials.csv` and `summary.csv`, their columns, their cell key, and the one rule
//! that picks a group's fastest cell.
//!
//! Field names are the column names. Times are seconds; an empty field means "not defined"
//! (chunks of a strategy without chunks, the stddev of one trial, any statistic of a failed
//! cell, anything unmeasurable on this OS). `status` is `ok` or `failed`; a failed cell's
//! `reason` says why, and its summary carries no statistic, speedup or efficiency: a bug must
//! never become a number.
//!
//! Columns added after the first release are appended at the end of each row (older readers
//! keep working): per trial `foreign_cpu_s, steal_s, load1` ([`crate::contention`]); per cell
//! the 95 % intervals `mean_ci_low_s, mean_ci_high_s, speedup_ci_low, speedup_ci_high`
//! ([`crate::results::intervals`]), `foreign_cpu_mean_s` and `contended` (some run's
//! contention window saw more foreign CPU than [`crate::contention::Threshold::allowed_s`]);
//! then `reference_shard`: in a shard of a sharded sweep (`sweep --shard I/K`) and in a merge
//! of shards, the shard I whose `seq` cell is the row's speedup denominator, which is the shard
//! that measured the row; empty in an unsharded sweep; then `pin` (both files) and `smt`
//! (summary) of `--pin`; then, since rounds, `phase` (both files) and per trial `round`,
//! `position`, `window_foreign_threads` and `contended`. The versions before rounds wrote a
//! last trial column `passes_alone` (crossbeam-pool's passes run alone, since removed), which
//! is read and ignored.

use serde::{Deserialize, Serialize};
use sph_strategies::StrategyName;

use super::key::{Cell, Group};
use crate::topology::Pin;
use sph_solver::models::Preset;
use sph_solver::sph::neighbors::NeighborMode;

/// The columns of `trials.csv`, in order.
pub const TRIAL_COLUMNS: [&str; 23] = [
    "strategy",
    "neighbors",
    "preset",
    "n",
    "steps",
    "cores",
    "chunks",
    "particles_per_chunk",
    "trial",
    "wall_s",
    "cpu_s",
    "checksum",
    "status",
    "reason",
    "foreign_cpu_s",
    "steal_s",
    "load1",
    "pin",
    "phase",
    "round",
    "position",
    "window_foreign_threads",
    "contended",
];

/// The columns of `summary.csv`, in order.
pub const SUMMARY_COLUMNS: [&str; 32] = [
    "strategy",
    "neighbors",
    "preset",
    "n",
    "steps",
    "cores",
    "chunks",
    "particles_per_chunk",
    "trials",
    "mean_s",
    "stddev_s",
    "min_s",
    "median_s",
    "max_s",
    "cpu_mean_s",
    "speedup",
    "efficiency",
    "outliers",
    "oversubscribed",
    "checksum",
    "status",
    "reason",
    "mean_ci_low_s",
    "mean_ci_high_s",
    "speedup_ci_low",
    "speedup_ci_high",
    "foreign_cpu_mean_s",
    "contended",
    "reference_shard",
    "pin",
    "smt",
    "phase",
];

/// How many leading columns of each file bench-sph 0.1.0 wrote before the contention and
/// confidence-interval columns were appended: a file with exactly those is an older sweep.
pub const LEGACY_TRIAL_COLUMNS: usize = 14;
/// See [`LEGACY_TRIAL_COLUMNS`].
pub const LEGACY_SUMMARY_COLUMNS: usize = 22;
/// The widths of `summary.csv` that earlier versions wrote, each a prefix of
/// [`SUMMARY_COLUMNS`]: the first release, then before `reference_shard`, before `pin` and
/// `smt`, and before `phase` (the last version that ran cells back to back).
const OLDER_SUMMARY_WIDTHS: [usize; 4] = [LEGACY_SUMMARY_COLUMNS, 28, 29, 31];
/// The widths of `trials.csv` that earlier versions wrote as prefixes of [`TRIAL_COLUMNS`]:
/// the first release, before `pin`, and before `passes_alone`.
const OLDER_TRIAL_WIDTHS: [usize; 3] = [LEGACY_TRIAL_COLUMNS, 17, 18];
/// The column the versions before rounds wrote last in `trials.csv` (crossbeam-pool's passes
/// run alone, since removed): read and ignored.
const RETIRED_TRIAL_COLUMN: &str = "passes_alone";

/// Whether `header` is the header of a `summary.csv` an earlier version wrote (read as it is,
/// the later columns empty).
pub fn is_older_summary_header(header: &[&str]) -> bool {
    OLDER_SUMMARY_WIDTHS
        .iter()
        .any(|&w| header == &SUMMARY_COLUMNS[..w])
}

/// Whether `header` is the header of a `trials.csv` an earlier version wrote (read as it is:
/// the later columns empty, `passes_alone` ignored).
pub fn is_older_trial_header(header: &[&str]) -> bool {
    let before_rounds = [&TRIAL_COLUMNS[..18], &[RETIRED_TRIAL_COLUMN][..]].concat();
    header == before_rounds.as_slice()
        || OLDER_TRIAL_WIDTHS
            .iter()
            .any(|&w| header == &TRIAL_COLUMNS[..w])
}

/// Which rounds of a sweep a row belongs to.
#[derive(
    Debug, Clone, Copy, Default, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize,
)]
#[serde(rename_all = "lowercase")]
pub enum Phase {
    /// The rounds over every cell of the plan: the charts' data, and where cells are chosen.
    #[default]
    Grid,
    /// The rounds that measure again each strategy's best cells, chosen by the grid: the
    /// findings' data (no winner's curse: these runs did not choose the cells).
    Confirm,
}

impl Phase {
    /// The name written in the CSVs.
    pub fn as_str(self) -> &'static str {
        match self {
            Phase::Grid => "grid",
            Phase::Confirm => "confirm",
        }
    }
}

/// Whether a cell's numbers can be used.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Status {
    /// Every run finished and reproduced the group's `seq` checksum.
    Ok,
    /// A run failed or its checksum differed: see `reason`.
    Failed,
}

impl Status {
    /// The word written in the CSVs.
    pub fn as_str(self) -> &'static str {
        match self {
            Status::Ok => "ok",
            Status::Failed => "failed",
        }
    }
}

/// Read by hand, so that a word other than `ok` and `failed` is named in the message (the
/// csv crate does not say which column an enum came from).
impl<'de> Deserialize<'de> for Status {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Status, D::Error> {
        let word = String::deserialize(d)?;
        match word.as_str() {
            "ok" => Ok(Status::Ok),
            "failed" => Ok(Status::Failed),
            other => Err(serde::de::Error::custom(format!(
                "status '{other}' is neither ok nor failed"
            ))),
        }
    }
}

/// One row of `trials.csv`: one timed run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TrialRow {
    /// Strategy.
    #[serde(with = "super::names::name")]
    pub strategy: StrategyName,
    /// Neighbour search.
    #[serde(with = "super::names::name")]
    pub neighbors: NeighborMode,
    /// Preset.
    #[serde(with = "super::names::name")]
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
    /// Where the cell's threads ran (`none`: wherever the operating system put them; empty in
    /// files written before `--pin`, read as `none`).
    #[serde(default, deserialize_with = "pin_or_none")]
    pub pin: Pin,
    /// The phase the run belongs to (`grid`, or `confirm` for the rounds that re-measure the
    /// chosen cells; `grid` in files written before phases).
    #[serde(default)]
    pub phase: Phase,
    /// The round of its phase the run ran in, from 1 (see [`crate::sweep::schedule`]); empty
    /// in files written before rounds.
    #[serde(default)]
    pub round: Option<usize>,
    /// The run's place in its round, from 1 (empty before rounds).
    #[serde(default)]
    pub position: Option<usize>,
    /// Hardware threads' worth of CPU that other work used over the run's contention window
    /// (foreign CPU seconds per wall second; see [`crate::sweep::windows`]); empty where
    /// unknown.
    #[serde(default)]
    pub window_foreign_threads: Option<f64>,
    /// Whether that window was contended for the run's cell; empty where unknown.
    #[serde(default)]
    pub contended: Option<bool>,
}

/// One row of `summary.csv`: one cell. Its first columns repeat [`TrialRow`]'s cell key on
/// purpose: the csv crate cannot write a nested (`flatten`ed) key struct as flat columns.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SummaryRow {
    /// Strategy.
    #[serde(with = "super::names::name")]
    pub strategy: StrategyName,
    /// Neighbour search.
    #[serde(with = "super::names::name")]
    pub neighbors: NeighborMode,
    /// Preset.
    #[serde(with = "super::names::name")]
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
    /// The speedup over the group's `seq`: the geometric mean of the per-round ratios of the
    /// round's `seq` time to this cell's ([`crate::results::intervals::paired_ratio`]; in
    /// files written before rounds, the ratio of the two means).
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
    /// Lower end of the 95 % Student-t interval of the mean wall seconds
    /// ([`crate::results::intervals`]; a bootstrap interval in files written before rounds).
    #[serde(default)]
    pub mean_ci_low_s: Option<f64>,
    /// Upper end of that interval.
    #[serde(default)]
    pub mean_ci_high_s: Option<f64>,
    /// Lower end of the 95 % interval of the speedup (the paired ratios' Student-t interval;
    /// a bootstrap interval in files written before rounds).
    #[serde(default)]
    pub speedup_ci_low: Option<f64>,
    /// Upper end of that interval.
    #[serde(default)]
    pub speedup_ci_high: Option<f64>,
    /// Mean foreign CPU seconds per trial (each trial's own window).
    #[serde(default)]
    pub foreign_cpu_mean_s: Option<f64>,
    /// Whether some run's contention window saw more foreign CPU than the threshold
    /// ([`TrialRow::contended`]); empty where unknown.
    #[serde(default)]
    pub contended: Option<bool>,
    /// The shard (1-based) whose `seq` cell is this row's speedup denominator: the shard that
    /// measured it (empty in an unsharded sweep).
    #[serde(default)]
    pub reference_shard: Option<usize>,
    /// Where the cell's threads ran (as in `trials.csv`).
    #[serde(default, deserialize_with = "pin_or_none")]
    pub pin: Pin,
    /// Whether the cell put threads on SMT siblings: more threads than physical cores, no more
    /// than hardware threads (empty where the topology is unknown).
    #[serde(default)]
    pub smt: Option<bool>,
    /// Which rounds the row summarises: `grid` (every cell of the plan) or `confirm` (the
    /// cells the grid chose, measured again in rounds of their own); `grid` in files written
    /// before phases.
    #[serde(default)]
    pub phase: Phase,
}

/// A `pin` field: a placement name, or empty (files written before `--pin`) for `none`.
fn pin_or_none<'de, D: serde::Deserializer<'de>>(d: D) -> Result<Pin, D::Error> {
    let text = String::deserialize(d)?;
    if text.is_empty() {
        return Ok(Pin::None);
    }
    text.parse().map_err(serde::de::Error::custom)
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
                    pin: self.pin,
                }
            }
        }
    };
}
keyed!(TrialRow);
keyed!(SummaryRow);

impl TrialRow {
    /// The row's cell and phase: a cell has one set of runs per phase.
    pub fn phased_key(&self) -> (Cell, Phase) {
        (self.key(), self.phase)
    }
}

impl SummaryRow {
    /// The row's cell and phase: a cell has one summary row per phase.
    pub fn phased_key(&self) -> (Cell, Phase) {
        (self.key(), self.phase)
    }
}

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
