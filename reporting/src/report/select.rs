//! Which rows of a study belong together: its groups, a group's strategies, core counts and
//! placements, and the series a chart line or a table row is drawn from ([`SeriesKey`]).
//!
//! A series is one strategy at one placement: pinned and unpinned cells of a strategy
//! (`sweep --pin`) are never pooled into one line, one best cell or one table row.

use std::collections::BTreeSet;
use std::fmt;

use sph_strategies::StrategyName;

use sph_harness::results::key::Group;
use sph_harness::results::rows::SummaryRow;
use sph_harness::topology::Pin;

/// The groups of `rows`, in the order they first appear.
pub fn groups(rows: &[SummaryRow]) -> Vec<Group> {
    let mut out: Vec<Group> = Vec::new();
    for r in rows {
        let g = r.group();
        if !out.contains(&g) {
            out.push(g);
        }
    }
    out
}

/// The rows of `group` that may be used.
pub fn ok_rows<'a>(rows: &'a [SummaryRow], group: &Group) -> Vec<&'a SummaryRow> {
    rows.iter()
        .filter(|r| r.group() == *group && r.is_usable())
        .collect()
}

/// The strategies of `group` in the order they first appear (the registry order of the plan).
pub fn strategies(rows: &[SummaryRow], group: &Group) -> Vec<StrategyName> {
    let mut out: Vec<StrategyName> = Vec::new();
    for r in rows.iter().filter(|r| r.group() == *group) {
        if !out.contains(&r.strategy) {
            out.push(r.strategy);
        }
    }
    out
}

/// One strategy's cells at one placement: what a line of the charts and a row of the tables
/// are drawn from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct SeriesKey {
    /// The strategy.
    pub strategy: StrategyName,
    /// Where its threads ran (`pin`).
    pub pin: Pin,
}

impl SeriesKey {
    /// `strategy` at placement `pin`.
    pub fn new(strategy: StrategyName, pin: Pin) -> SeriesKey {
        SeriesKey { strategy, pin }
    }

    /// `strategy`'s unpinned cells (`pin = none`).
    pub fn unpinned(strategy: StrategyName) -> SeriesKey {
        SeriesKey::new(strategy, Pin::None)
    }

    /// Whether a row belongs to the series (any group).
    pub fn holds(&self, r: &SummaryRow) -> bool {
        r.strategy == self.strategy && r.pin == self.pin
    }
}

/// `rayon-chunks` unpinned, `rayon-chunks (spread)` pinned: legends, tables and findings.
impl fmt::Display for SeriesKey {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.pin {
            Pin::None => write!(f, "{}", self.strategy),
            pin => write!(f, "{} ({pin})", self.strategy),
        }
    }
}

/// The placements `strategy` was measured at in `group`, `none` first, then `compact`,
/// `spread`.
pub fn pins(rows: &[SummaryRow], group: &Group, strategy: StrategyName) -> Vec<Pin> {
    let set: BTreeSet<Pin> = rows
        .iter()
        .filter(|r| r.group() == *group && r.strategy == strategy)
        .map(|r| r.pin)
        .collect();
    set.into_iter().collect()
}

/// The series of `group` (every strategy but `seq`): the strategies in the order they first
/// appear, each at its placements in the order of [`pins`].
pub fn series(rows: &[SummaryRow], group: &Group) -> Vec<SeriesKey> {
    strategies(rows, group)
        .into_iter()
        .filter(|&s| s != StrategyName::Seq)
        .flat_map(|s| {
            pins(rows, group, s)
                .into_iter()
                .map(move |p| SeriesKey::new(s, p))
        })
        .collect()
}

/// Whether some cell of `group` was pinned (`seq` never is): the report then names each
/// cell's placement.
pub fn is_pinned(rows: &[SummaryRow], group: &Group) -> bool {
    rows.iter()
        .any(|r| r.group() == *group && r.pin != Pin::None)
}

/// Whether `strategy` has cells with a chunks value in `group`.
pub fn is_chunked(rows: &[SummaryRow], group: &Group, strategy: StrategyName) -> bool {
    rows.iter()
        .any(|r| r.group() == *group && r.strategy == strategy && r.chunks.is_some())
}

/// The distinct core counts of the usable cells of `group` (any strategy but `seq`).
pub fn cores(rows: &[SummaryRow], group: &Group) -> Vec<usize> {
    let set: BTreeSet<usize> = ok_rows(rows, group)
        .iter()
        .filter(|r| !r.is_reference())
        .map(|r| r.cores)
        .collect();
    set.into_iter().collect()
}
