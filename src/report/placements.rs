//! Placements (`sweep --pin`) of one strategy set against each other, cell against cell: at
//! each core count where both were measured without contention with the same chunks (the
//! chunks value fastest under either), one placement is called faster only where the two 95 %
//! intervals of the mean are apart; overlapping intervals are indistinguishable within the
//! trial spread, and cells without intervals give no order. Each strategy gets one sentence
//! per pair of placements (`compact` against `spread`, each pinned one against `none`): where
//! each is faster, where the intervals cannot tell, and the largest difference with both
//! cells' speedups and their intervals. [`compare`] decides, [`Placements::sentence`] words.

use super::findings::and_list;
use super::numbers::{interval, secs, times};
use super::series::{self, Best, Group};
use crate::results::rows::SummaryRow;
use crate::topology::Pin;
use sph_strategies::StrategyName;

/// Placement `a` of a strategy against placement `b`
/// ([`super::findings::Finding::Placements`]), cell against cell: at each core count where
/// both were measured without contention with the same chunks, the chunks value fastest
/// under either.
#[derive(Debug, Clone, PartialEq)]
pub struct Placements {
    /// The strategy.
    pub strategy: StrategyName,
    /// The placement compared…
    pub a: Pin,
    /// …against this one.
    pub b: Pin,
    /// The pairs of cells, by cores.
    pub at: Vec<PinPair>,
    /// Whether the strategy has chunks (the sentence says how they were chosen).
    pub chunked: bool,
    /// Whether speedups may be stated (a trusted reference); otherwise times are.
    pub show_speedup: bool,
    /// Core counts where both were measured, but only with contended cells: left out.
    pub contended: usize,
}

/// One core count of [`Placements`]: the two cells, same cores and chunks.
#[derive(Debug, Clone, PartialEq)]
pub struct PinPair {
    /// Placement `a`'s cell.
    pub a: Best,
    /// Placement `b`'s cell.
    pub b: Best,
}

/// What the intervals say about a [`PinPair`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PinOrder {
    /// Placement `a` is faster: the 95 % intervals of the mean are apart.
    AFaster,
    /// Placement `b` is faster: the intervals are apart.
    BFaster,
    /// The intervals overlap.
    Indistinguishable,
    /// A cell has no interval (one trial, an older sweep): no order can be told.
    NoIntervals,
}

impl PinPair {
    /// The order the intervals support.
    pub fn order(&self) -> PinOrder {
        match (self.a.mean_ci, self.b.mean_ci) {
            (Some(x), Some(y)) if x.overlaps(&y) => PinOrder::Indistinguishable,
            (Some(_), Some(_)) if self.a.mean_s < self.b.mean_s => PinOrder::AFaster,
            (Some(_), Some(_)) => PinOrder::BFaster,
            _ => PinOrder::NoIntervals,
        }
    }

    /// The relative difference of the two means, over the faster one.
    fn difference(&self) -> f64 {
        (self.a.mean_s - self.b.mean_s).abs() / self.a.mean_s.min(self.b.mean_s)
    }
}

/// The pairs of placements compared, each as (a, b): `compact` against `spread`, then each
/// pinned placement against `none`.
const PIN_PAIRS: [(Pin, Pin); 3] = [
    (Pin::Compact, Pin::Spread),
    (Pin::Spread, Pin::None),
    (Pin::Compact, Pin::None),
];

/// Per strategy of `strategies` measured at two placements or more in `g`, one comparison per
/// pair of them (`compact` against `spread`, each pinned one against `none`); speedups are
/// stated with `show_speedup` (the group's `seq` reference is trusted), times otherwise.
pub fn compare<'a>(
    rows: &'a [SummaryRow],
    g: &'a Group,
    strategies: &'a [StrategyName],
    show_speedup: bool,
) -> impl Iterator<Item = Placements> + 'a {
    strategies.iter().flat_map(move |&s| {
        let pins = series::pins(rows, g, s);
        PIN_PAIRS
            .iter()
            .filter(move |(a, b)| pins.contains(a) && pins.contains(b))
            .filter_map(move |&(a, b)| placement_pair(rows, g, s, (a, b), show_speedup))
    })
}

/// Placement `a` of `s` against `b`, where some core count has both (`None` where none has).
fn placement_pair(
    rows: &[SummaryRow],
    g: &Group,
    s: StrategyName,
    (a, b): (Pin, Pin),
    show_speedup: bool,
) -> Option<Placements> {
    let ok = series::ok_rows(rows, g);
    let cell = |pin: Pin, cores: usize, chunks: Option<usize>| {
        ok.iter()
            .find(|r| r.strategy == s && r.pin == pin && r.cores == cores && r.chunks == chunks)
            .and_then(|r| Best::of(r))
    };
    let mut at = Vec::new();
    let mut contended = 0;
    for c in series::cores(rows, g) {
        let both: Vec<PinPair> = ok
            .iter()
            .filter(|r| r.strategy == s && r.pin == a && r.cores == c)
            .filter_map(|r| {
                Some(PinPair {
                    a: cell(a, c, r.chunks)?,
                    b: cell(b, c, r.chunks)?,
                })
            })
            .collect();
        let calm = both.iter().filter(|p| !p.a.contended && !p.b.contended);
        // The chunks value fastest under either placement.
        match calm.min_by(|x, y| {
            let fastest = |p: &PinPair| p.a.mean_s.min(p.b.mean_s);
            fastest(x).total_cmp(&fastest(y))
        }) {
            Some(p) => at.push(p.clone()),
            None if !both.is_empty() => contended += 1,
            None => {}
        }
    }
    (!at.is_empty() || contended > 0).then_some(Placements {
        strategy: s,
        a,
        b,
        at,
        chunked: series::is_chunked(rows, g, s),
        show_speedup,
        contended,
    })
}

/// A placement as the findings name it: `unpinned`, or `spread` in code style.
pub(super) fn pin_name(pin: Pin) -> String {
    match pin {
        Pin::None => "unpinned".to_owned(),
        pin => format!("`{pin}`"),
    }
}

impl Placements {
    /// The comparison in one sentence: where each placement is faster, where the intervals
    /// cannot tell, and the largest difference with both cells' numbers.
    pub fn sentence(&self) -> String {
        let (a, b) = (pin_name(self.a), pin_name(self.b));
        let cores_where = |order: PinOrder| -> Vec<usize> {
            self.at
                .iter()
                .filter(|p| p.order() == order)
                .map(|p| p.a.cores)
                .collect()
        };
        let mut parts = Vec::new();
        for (order, phrase) in [
            (
                PinOrder::AFaster,
                format!("{a} is faster (95 % intervals of the mean apart)"),
            ),
            (
                PinOrder::BFaster,
                format!("{b} is faster (95 % intervals of the mean apart)"),
            ),
            (
                PinOrder::Indistinguishable,
                "they are indistinguishable within the trial spread".to_owned(),
            ),
            (
                PinOrder::NoIntervals,
                "the cells have no confidence intervals, so no order can be told".to_owned(),
            ),
        ] {
            let cores = cores_where(order);
            if !cores.is_empty() {
                parts.push(format!("{phrase} at {}", cores_list(&cores)));
            }
        }
        let how = if self.chunked {
            " (at each core count, the chunks value fastest under either)"
        } else {
            ""
        };
        let left_out = match self.contended {
            0 => String::new(),
            1 => "; 1 core count had only contended cells and is left out".to_owned(),
            k => format!("; {k} core counts had only contended cells and are left out"),
        };
        let head = format!("{}, {a} against {b}{how}", self.strategy);
        let Some(largest) = self
            .at
            .iter()
            .max_by(|x, y| x.difference().total_cmp(&y.difference()))
        else {
            return format!("{head}: no core count was measured without contention{left_out}.");
        };
        if largest.difference() == 0.0 {
            return format!(
                "{head}: {}, where their means are equal{left_out}.",
                parts.join("; ")
            );
        }
        let value = |c: &Best| match c.speedup.filter(|_| self.show_speedup) {
            Some(s) => format!("{}{}", times(s), interval(c.speedup_ci)),
            None => format!("{} s{}", secs(c.mean_s), interval(c.mean_ci)),
        };
        let unit = if self.show_speedup && largest.a.speedup.is_some() {
            " over seq"
        } else {
            ""
        };
        let place = format!(
            "{}{}",
            series::cores_label(largest.a.cores),
            largest
                .a
                .chunks
                .map_or_else(String::new, |k| format!(" with {k} chunks"))
        );
        let numbers = format!(
            "{a} {} against {b} {}{unit}",
            value(&largest.a),
            value(&largest.b)
        );
        if self.at.len() == 1 {
            format!(
                "{head}: {} ({place}: {numbers}){left_out}.",
                parts.join("; ")
            )
        } else {
            format!(
                "{head}: {}; the largest difference is at {place}: {numbers}{left_out}.",
                parts.join("; ")
            )
        }
    }
}

/// Core counts as `1 core`, `2 and 4 cores`, `2, 4 and 8 cores`.
fn cores_list(cores: &[usize]) -> String {
    match cores {
        [one] => series::cores_label(*one),
        _ => format!(
            "{} cores",
            and_list(&cores.iter().map(|c| c.to_string()).collect::<Vec<_>>())
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::report::findings::tests::with_ci;
    use crate::report::findings::{Finding, findings};
    use crate::report::series::tests::pinned;
    use crate::results::rows::tests::row;

    fn sentences(rows: &[SummaryRow], g: &Group) -> Vec<String> {
        findings(rows, g).iter().map(Finding::sentence).collect()
    }

    #[test]
    fn placements_apart_name_the_faster_one_and_overlapping_ones_are_indistinguishable() {
        use StrategyName::RayonChunks;
        let rows = vec![
            row(StrategyName::Seq, 1, None, 4.0),
            with_ci(row(RayonChunks, 1, Some(10), 3.9), 3.8, 4.0),
            with_ci(
                pinned(row(RayonChunks, 1, Some(10), 3.95), Pin::Spread),
                3.85,
                4.05,
            ),
            with_ci(row(RayonChunks, 2, Some(10), 2.2), 2.1, 2.3),
            with_ci(
                pinned(row(RayonChunks, 2, Some(10), 1.8), Pin::Spread),
                1.7,
                1.9,
            ),
            // Spread's 5 chunks have no unpinned twin: not compared, though faster.
            with_ci(
                pinned(row(RayonChunks, 2, Some(5), 1.0), Pin::Spread),
                0.9,
                1.1,
            ),
        ];
        let f = sentences(&rows, &rows[0].group());
        let compared = |s: &&String| s.contains("` against ");
        let s = f.iter().find(compared).unwrap();
        assert_eq!(
            s,
            "rayon-chunks, `spread` against unpinned (at each core count, the chunks value \
             fastest under either): `spread` is faster (95 % intervals of the mean apart) at \
             2 cores; they are indistinguishable within the trial spread at 1 core; the \
             largest difference is at 2 cores with 10 chunks: `spread` 2.22× [2.11–2.33] \
             against unpinned 1.82× [1.73–1.91] over seq."
        );
        assert_eq!(f.iter().filter(compared).count(), 1, "{f:#?}");
        assert!(
            f.iter().any(|s| s.starts_with(
                "rayon-chunks (spread): more chunks stop paying (no larger chunk count is \
                 faster by more than the trial spread) from 5 chunks at 2 cores."
            )),
            "{f:#?}"
        );
        // Pinned cells are named as such wherever a finding names a cell.
        assert!(
            f.iter()
                .any(|s| s.contains("**rayon-chunks (spread) with 5 chunks (1.00 s")),
            "{f:?}"
        );
        // One sentence for the noise at 1 core, over both placements.
        let noise: Vec<&String> = f.iter().filter(|s| s.contains("noise")).collect();
        assert_eq!(noise.len(), 1, "{noise:?}");
        assert_eq!(
            noise[0],
            "rayon-chunks's speedups of 1.03× [0.974–1.08] (unpinned) and 1.01× [0.962–1.06] \
             (`spread`) at 1 core are noise in the seq reference, not a win: one worker runs \
             the same passes as seq."
        );
    }

    #[test]
    fn compact_against_spread_with_overlapping_intervals_claims_no_order() {
        use StrategyName::StdStatic;
        let rows = vec![
            row(StrategyName::Seq, 1, None, 4.0),
            with_ci(pinned(row(StdStatic, 2, None, 2.0), Pin::Compact), 1.9, 2.1),
            with_ci(
                pinned(row(StdStatic, 2, None, 2.05), Pin::Spread),
                1.95,
                2.15,
            ),
        ];
        let f = sentences(&rows, &rows[0].group());
        let s = f.iter().find(|s| s.contains("against")).unwrap();
        assert_eq!(
            s,
            "std-static, `compact` against `spread`: they are indistinguishable within the \
             trial spread at 2 cores (2 cores: `compact` 2.00× [1.90–2.10] against `spread` \
             1.95× [1.85–2.05] over seq)."
        );
        assert!(!s.contains("faster"), "{s}");
    }

    #[test]
    fn without_intervals_two_placements_get_no_order() {
        let mut none = row(StrategyName::RayonIter, 2, None, 2.0);
        none.mean_ci_low_s = None;
        let rows = vec![
            row(StrategyName::Seq, 1, None, 4.0),
            none,
            pinned(row(StrategyName::RayonIter, 2, None, 1.0), Pin::Spread),
        ];
        let f = sentences(&rows, &rows[0].group()).join("\n");
        assert!(
            f.contains(
                "the cells have no confidence intervals, so no order can be told at 2 cores"
            ),
            "{f}"
        );
        assert!(!f.contains("is faster (95 %"), "{f}");
    }
}
