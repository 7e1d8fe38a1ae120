//! One cell's numbers as the report reads them: its runs by round, which comparisons pair
//! ([`Runs`], [`Batch`]), and a best cell's times, speedup and intervals ([`Best`]).

use sph_harness::results::intervals::{self, Ratio};
use sph_harness::results::rows::{Phase, SummaryRow};
use sph_harness::results::stats::Interval;
use sph_harness::topology::Pin;
use sph_strategies::StrategyName;

use super::select::SeriesKey;

/// The runs that may be paired with each other: one sweep's, one phase's, one shard's.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Batch {
    /// The sweep, by its place in the study.
    pub source: usize,
    /// Grid or confirmation rounds.
    pub phase: Phase,
    /// The shard that measured the cell (`reference_shard`), in a sharded sweep or a merge.
    pub shard: Option<usize>,
    /// Whether the sweep's rounds pair at all ([`Design::pairs`](super::view::Design::pairs)).
    pub paired: bool,
}

/// A cell's ok runs of one phase.
#[derive(Debug, Clone, PartialEq)]
pub struct Runs {
    /// What they may be paired with.
    pub batch: Batch,
    /// (round, wall seconds), in trial order.
    pub rounds: Vec<(usize, f64)>,
}

impl Runs {
    /// These runs' times over `other`'s, paired by round ([`intervals::paired_ratio`]): below
    /// 1 these are faster. `None` where the two cannot be paired (other rounds, no rounds in
    /// common, a sweep whose rounds do not pair).
    pub fn ratio(&self, other: &Runs) -> Option<Ratio> {
        if self.batch != other.batch || !self.batch.paired {
            return None;
        }
        intervals::paired_ratio(&self.rounds, &other.rounds)
    }

    /// The wall seconds of each run.
    pub fn walls(&self) -> impl Iterator<Item = f64> + '_ {
        self.rounds.iter().map(|&(_, w)| w)
    }
}

/// A strategy's best cell at one core count ([`GroupView::best_per_cores`](super::view::GroupView::best_per_cores)), or any cell
/// with its runs.
#[derive(Debug, Clone, PartialEq)]
pub struct Best {
    /// The strategy.
    pub strategy: StrategyName,
    /// Worker threads.
    pub cores: usize,
    /// Chunks of the cell (`None` for strategies without chunks).
    pub chunks: Option<usize>,
    /// Where its threads ran.
    pub pin: Pin,
    /// Mean wall seconds.
    pub mean_s: f64,
    /// Median wall seconds.
    pub median_s: f64,
    /// Fastest trial.
    pub min_s: f64,
    /// The speedup over the group's `seq` of the same rounds (paired by round).
    pub speedup: Option<f64>,
    /// Speedup over cores.
    pub efficiency: Option<f64>,
    /// More threads than the machine has.
    pub oversubscribed: bool,
    /// 95 % interval of the typical seconds (`None` under 3 trials or in an older sweep).
    pub mean_ci: Option<Interval>,
    /// 95 % interval of the speedup.
    pub speedup_ci: Option<Interval>,
    /// Other work used the machine while it was measured.
    pub contended: bool,
    /// Whether its numbers come from confirmation rounds, which did not choose it; `false`:
    /// from the grid's rounds, which chose it too (biased fast).
    pub confirmed: bool,
    /// Its runs, by round: what comparisons pair.
    pub runs: Runs,
    /// Where `runs` are the confirmation's: the same cell's runs in the grid's rounds, which
    /// pair with a strategy the confirmation left out (more than twice the fastest cell's
    /// time: the grid settled that it lost).
    pub grid_runs: Option<Runs>,
}

/// How tables flag a cell with more threads than the machine has.
pub const OVERSUBSCRIBED: &str = "⚠ oversubscribed";
/// How tables flag a cell that other work disturbed.
pub const CONTENDED: &str = "⚠ contended";

impl Best {
    /// Its flags: [`OVERSUBSCRIBED`] and [`CONTENDED`] where they apply.
    pub fn flags(&self) -> impl Iterator<Item = &'static str> {
        [
            (self.oversubscribed, OVERSUBSCRIBED),
            (self.contended, CONTENDED),
        ]
        .into_iter()
        .filter_map(|(on, flag)| on.then_some(flag))
    }

    /// A usable cell's numbers with its `runs` (`None` without a mean).
    pub fn of(r: &SummaryRow, runs: Runs) -> Option<Best> {
        let mean_s = r.mean_s?;
        Some(Best {
            strategy: r.strategy,
            cores: r.cores,
            chunks: r.chunks,
            pin: r.pin,
            mean_s,
            median_s: r.median_s.unwrap_or(mean_s),
            min_s: r.min_s.unwrap_or(mean_s),
            speedup: r.speedup,
            efficiency: r.efficiency,
            oversubscribed: r.oversubscribed,
            mean_ci: interval(r.mean_ci_low_s, r.mean_ci_high_s),
            speedup_ci: interval(r.speedup_ci_low, r.speedup_ci_high),
            contended: r.contended == Some(true),
            confirmed: r.phase == Phase::Confirm,
            runs,
            grid_runs: None,
        })
    }

    /// Its runs in the grid's rounds: [`Best::grid_runs`], or its own runs where they are the
    /// grid's.
    pub fn grid(&self) -> &Runs {
        self.grid_runs.as_ref().unwrap_or(&self.runs)
    }

    /// The series it belongs to.
    pub fn key(&self) -> SeriesKey {
        SeriesKey::new(self.strategy, self.pin)
    }

    /// The Karp–Flatt serial fraction at this cell with its 95 % interval, the speedup's
    /// carried through [`karp_flatt`] (which falls as the speedup rises); `None` without an
    /// interval, at a speedup of 1 or less, and wherever the interval reaches 0 or below.
    pub fn serial_fraction(&self) -> Option<(f64, Interval)> {
        let s = self.speedup.filter(|&s| s > 1.0)?;
        let i = self.speedup_ci?;
        let e = karp_flatt(s, self.cores)?;
        let low = karp_flatt(i.high, self.cores)?;
        let high = karp_flatt(i.low, self.cores)?;
        (low > 0.0).then_some((e, Interval { low, high }))
    }
}

/// An interval from its two ends, if both are known.
pub fn interval(low: Option<f64>, high: Option<f64>) -> Option<Interval> {
    Some(Interval {
        low: low?,
        high: high?,
    })
}

/// The Karp–Flatt experimentally determined serial fraction
/// `e = (1/S − 1/p) / (1 − 1/p)` for speedup `S` on `p` processors; undefined for `p = 1`.
pub fn karp_flatt(speedup: f64, p: usize) -> Option<f64> {
    if p < 2 || !(speedup.is_finite() && speedup > 0.0) {
        return None;
    }
    let p = p as f64;
    Some((1.0 / speedup - 1.0 / p) / (1.0 - 1.0 / p))
}
