//! Placements (`sweep --pin`) of one strategy set against each other, cell against cell: at
//! each core count where both were measured without contention with the same chunks (the
//! chunks value fastest under either), among the cells the findings rest on (the confirmation
//! rounds' where the group has them), one placement is called faster only where the 95 %
//! interval of their time ratio, paired by round ([`verdict::order`]), excludes 1; otherwise
//! they are not distinguishable, and without an interval no order is told. Each strategy gets
//! one sentence per pair of placements (`compact` against `spread`, each pinned one against
//! `none`): where each is faster, where the rounds cannot tell, and the largest difference
//! with both cells' speedups. [`compare`] decides, [`Placements::sentence`] words.

use super::cell::Best;
use super::numbers::{interval, plus_minus, secs};
use super::select;
use super::series;
use super::verdict;
use super::verdict::{Order, and_list};
use super::view::GroupView;
use sph_harness::topology::Pin;
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

impl PinPair {
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

/// Per strategy of `strategies` measured at two placements or more in the group of `view`,
/// one comparison per pair of them (`compact` against `spread`, each pinned one against
/// `none`); speedups are stated with `show_speedup` (the group's `seq` reference is trusted),
/// times otherwise.
pub fn compare<'a>(
    view: &'a GroupView,
    strategies: &'a [StrategyName],
    show_speedup: bool,
) -> impl Iterator<Item = Placements> + 'a {
    strategies.iter().flat_map(move |&s| {
        let pins = select::pins(&view.rows, &view.group, s);
        PIN_PAIRS
            .iter()
            .filter(move |(a, b)| pins.contains(a) && pins.contains(b))
            .filter_map(move |&(a, b)| placement_pair(view, s, (a, b), show_speedup))
    })
}

/// Placement `a` of `s` against `b`, where some core count has both (`None` where none has).
fn placement_pair(
    view: &GroupView,
    s: StrategyName,
    (a, b): (Pin, Pin),
    show_speedup: bool,
) -> Option<Placements> {
    let ok = select::ok_rows(view.findings_rows(), &view.group);
    let cell = |pin: Pin, cores: usize, chunks: Option<usize>| {
        ok.iter()
            .find(|r| r.strategy == s && r.pin == pin && r.cores == cores && r.chunks == chunks)
            .and_then(|r| view.best(r))
    };
    let mut at = Vec::new();
    let mut contended = 0;
    for c in view.cores() {
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
        chunked: select::is_chunked(&view.rows, &view.group, s),
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
        // What the paired rounds say of a pair, as the place of its phrase below.
        let said = |p: &PinPair| match verdict::order(&p.a, &p.b) {
            Order::AFaster(_) => 0,
            Order::BFaster(_) => 1,
            Order::Unresolved(_) => 2,
            Order::Unknown(_) => 3,
        };
        let mut parts = Vec::new();
        for (i, phrase) in [
            format!("{a} is faster (paired rounds)"),
            format!("{b} is faster (paired rounds)"),
            "they are not distinguishable".to_owned(),
            "the paired rounds give no interval, so no order can be told".to_owned(),
        ]
        .into_iter()
        .enumerate()
        {
            let cores: Vec<usize> = self
                .at
                .iter()
                .filter(|p| said(p) == i)
                .map(|p| p.a.cores)
                .collect();
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
            Some(s) => plus_minus(s, c.speedup_ci),
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
    use crate::report::view::tests::{Spec, of_rows, view};
    use StrategyName::{Seq, StdStatic};
    use sph_harness::results::fixtures::row;

    /// `seq`'s times by round.
    const SEQ: [f64; 3] = [4.0, 4.8, 3.2];

    /// The placement sentences of `v`, as the findings word them (its `seq` trusted).
    fn sentences_of(v: &GroupView) -> Vec<String> {
        compare(v, &v.parallel_strategies(), true)
            .map(|p| p.sentence())
            .collect()
    }

    fn sentences(specs: &[Spec<'_>]) -> Vec<String> {
        sentences_of(&view(specs))
    }

    #[test]
    fn compact_against_spread_with_rounds_that_disagree_claims_no_order() {
        let f = sentences(&[
            (Seq, 1, None, Pin::None, &SEQ),
            (StdStatic, 2, None, Pin::Compact, &[2.0, 2.5, 1.5]),
            (StdStatic, 2, None, Pin::Spread, &[2.1, 2.3, 1.65]),
        ]);
        let s = f.iter().find(|s| s.contains("against")).unwrap();
        assert!(
            s.starts_with(
                "std-static, `compact` against `spread`: they are not distinguishable at 2 \
                 cores (2 cores: `compact` "
            ),
            "{s}"
        );
        assert!(!s.contains("faster"), "{s}");
    }

    #[test]
    fn cells_whose_runs_do_not_pair_get_no_order() {
        let mut spread = row(StrategyName::RayonIter, 2, None, 1.0);
        spread.pin = Pin::Spread;
        let v = of_rows(vec![
            row(Seq, 1, None, 4.0),
            row(StrategyName::RayonIter, 2, None, 2.0),
            spread,
        ]);
        let f = sentences_of(&v);
        let f = f.join("\n");
        assert!(
            f.contains("the paired rounds give no interval, so no order can be told at 2 cores"),
            "{f}"
        );
        assert!(!f.contains("is faster"), "{f}");
    }
}
