//! Whether a second sweep on the same machine reproduces the first: `bench-sph report A B
//! --compare` of directories measured on the same hardware. Per pair of such sides
//! ([`pairs`]):
//!
//! - the cells both measured, matched by cell and phase, and the share of them whose 95 %
//!   speedup intervals overlap, and whose intervals of the time overlap;
//! - every ranking (one strategy's best cell faster than another's at a core count, by their
//!   paired rounds: [`verdict::order`]) resolved on one side and reversed, or not resolved,
//!   on the other. Contended cells enter no ranking.
//!
//! Sides of different machines are a comparison of machines ([`super::plan`]), never this.

use std::collections::HashMap;
use std::fmt::Write as _;

use super::sides::{Side, same_hardware_sets};
use crate::report::cell;
use crate::report::numbers::{faster, percent, plus_minus};
use crate::report::select::SeriesKey;
use crate::report::series::Group;
use crate::report::table::{Column, Table};
use crate::report::verdict;
use crate::report::verdict::Order;
use sph_harness::results::key::{Cell, LabelStyle};
use sph_harness::results::rows::{Phase, SummaryRow};
use sph_harness::results::stats::Interval;

/// How well side `second` reproduces side `first`.
#[derive(Debug, Clone, PartialEq)]
pub struct Reproduced {
    /// The first side, by index.
    pub first: usize,
    /// The second side.
    pub second: usize,
    /// Cells (cell and phase) usable on both sides.
    pub cells: usize,
    /// (overlapping, compared): the cells with a speedup interval on both sides, and of those
    /// the ones whose intervals overlap.
    pub speedups: (usize, usize),
    /// The same for the intervals of the time.
    pub times: (usize, usize),
    /// Rankings resolved on at least one side.
    pub rankings: usize,
    /// Of those, the ones resolved on one side and reversed or not resolved on the other.
    pub changed: Vec<Changed>,
}

/// One ranking that did not reproduce: strategy `a` against `b` at `cores` in `group`.
#[derive(Debug, Clone, PartialEq)]
pub struct Changed {
    /// The workload.
    pub group: Group,
    /// Worker threads.
    pub cores: usize,
    /// The first series…
    pub a: SeriesKey,
    /// …against this one.
    pub b: SeriesKey,
    /// What the first side's paired rounds say.
    pub first: Order,
    /// What the second side's say.
    pub second: Order,
}

impl Changed {
    /// Whether each side resolved the ranking, the other way round.
    pub fn reversed(&self) -> bool {
        matches!(
            (self.first, self.second),
            (Order::AFaster(_), Order::BFaster(_)) | (Order::BFaster(_), Order::AFaster(_))
        )
    }
}

/// Each pair of sides that ran on the same hardware, the earlier first.
pub fn pairs(sides: &[Side<'_>]) -> Vec<Reproduced> {
    let mut out = Vec::new();
    for set in same_hardware_sets(sides) {
        for (n, &i) in set.iter().enumerate() {
            for &j in &set[n + 1..] {
                out.push(reproduced((i, &sides[i]), (j, &sides[j])));
            }
        }
    }
    out
}

/// How `second` reproduces `first`.
fn reproduced((i, first): (usize, &Side<'_>), (j, second): (usize, &Side<'_>)) -> Reproduced {
    let cells = |side: &Side<'_>| -> HashMap<(Cell, Phase), SummaryRow> {
        side.views
            .iter()
            .flat_map(|v| v.rows.iter().chain(&v.confirmed))
            .filter(|r| r.is_usable())
            .map(|r| (r.phased_key(), r.clone()))
            .collect()
    };
    let theirs = cells(second);
    let both: Vec<(SummaryRow, &SummaryRow)> = cells(first)
        .into_values()
        .filter_map(|r| {
            let other = theirs.get(&r.phased_key())?;
            Some((r, other))
        })
        .collect();
    let overlap = |f: fn(&SummaryRow) -> Option<Interval>| {
        let known: Vec<bool> = both
            .iter()
            .filter_map(|(a, b)| Some(f(a)?.overlaps(&f(b)?)))
            .collect();
        (known.iter().filter(|&&o| o).count(), known.len())
    };
    let (rankings, changed) = rankings(first, second);
    Reproduced {
        first: i,
        second: j,
        cells: both.len(),
        speedups: overlap(|r| cell::interval(r.speedup_ci_low, r.speedup_ci_high)),
        times: overlap(|r| cell::interval(r.mean_ci_low_s, r.mean_ci_high_s)),
        rankings,
        changed,
    }
}

/// The rankings resolved on at least one side (their number), and those that did not
/// reproduce.
fn rankings(first: &Side<'_>, second: &Side<'_>) -> (usize, Vec<Changed>) {
    let (mut resolved, mut changed) = (0, Vec::new());
    for v in &first.views {
        let Some(w) = second.view(&v.group) else {
            continue;
        };
        let (ours, theirs) = (v.series_bests(), w.series_bests());
        let at = |bests: &[(SeriesKey, Vec<cell::Best>)], k: SeriesKey, c: usize| {
            bests
                .iter()
                .find(|(key, _)| *key == k)
                .and_then(|(_, b)| b.iter().find(|b| b.cores == c && !b.contended))
                .cloned()
        };
        for c in v.cores() {
            for (n, (a, _)) in ours.iter().enumerate() {
                for (b, _) in &ours[n + 1..] {
                    let (Some(a1), Some(b1), Some(a2), Some(b2)) = (
                        at(&ours, *a, c),
                        at(&ours, *b, c),
                        at(&theirs, *a, c),
                        at(&theirs, *b, c),
                    ) else {
                        continue;
                    };
                    let (o1, o2) = (verdict::order(&a1, &b1), verdict::order(&a2, &b2));
                    if !(o1.resolved() || o2.resolved()) {
                        continue;
                    }
                    resolved += 1;
                    let same = matches!(
                        (o1, o2),
                        (Order::AFaster(_), Order::AFaster(_))
                            | (Order::BFaster(_), Order::BFaster(_))
                    );
                    if !same {
                        changed.push(Changed {
                            group: v.group,
                            cores: c,
                            a: *a,
                            b: *b,
                            first: o1,
                            second: o2,
                        });
                    }
                }
            }
        }
    }
    (resolved, changed)
}

/// The reproducibility sections of `reproduced`, sides named by `tags` (empty for none).
pub fn markdown(reproduced: &[Reproduced], tags: &[&str]) -> String {
    let mut md = String::new();
    for r in reproduced {
        let (a, b) = (tags[r.first], tags[r.second]);
        let share = |(k, n): (usize, usize)| match n {
            0 => "none has an interval on both sides".to_owned(),
            n => format!("{k} of {n} ({})", percent(k as f64 / n as f64 * 100.0)),
        };
        if r.cells == 0 {
            let _ = writeln!(
                md,
                "## Reproducibility: {b} against {a}\n\n{a} and {b} ran on the same machine, but \
                 no cell was measured on both (matched by cell and phase: preset, neighbour \
                 search, N, steps, strategy, cores, chunks): they cannot say whether one \
                 reproduces the other.\n"
            );
            continue;
        }
        let reversed = r.changed.iter().filter(|c| c.reversed()).count();
        let _ = writeln!(
            md,
            "## Reproducibility: {b} against {a}\n\n{a} and {b} ran on the same machine, so \
             {b} is a second measurement of what {a} measured. Of the {} cells both measured \
             (matched by cell and phase), the 95 % speedup intervals overlap in {} and the \
             intervals of the time in {}. Rankings (one strategy's best cell faster than \
             another's at a core count, by their paired rounds) resolved on either side: {}; \
             reversed on the other: {reversed}; resolved on one side only: {}.\n",
            r.cells,
            share(r.speedups),
            share(r.times),
            r.rankings,
            r.changed.len() - reversed,
        );
        if r.changed.is_empty() {
            continue;
        }
        let mut t = Table::new([
            Column::left("workload"),
            Column::right("cores"),
            Column::left("strategy"),
            Column::left(format!("on {a}")),
            Column::left(format!("on {b}")),
            Column::left(""),
        ]);
        for c in &r.changed {
            let how = if c.reversed() {
                "**reversed**"
            } else {
                "resolved on one side only"
            };
            t.row([
                c.group.label(LabelStyle::Report),
                c.cores.to_string(),
                c.a.to_string(),
                said(&c.first, c),
                said(&c.second, c),
                how.to_owned(),
            ]);
        }
        let _ = writeln!(md, "{t}");
    }
    md
}

/// What one side says of a changed ranking, of its first strategy.
fn said(o: &Order, c: &Changed) -> String {
    match o {
        Order::AFaster(r) | Order::BFaster(r) => faster(r, &c.b.to_string()),
        Order::Unresolved(r) => format!(
            "not distinguishable from {}, {}",
            c.b,
            plus_minus(r.value, r.interval)
        ),
        Order::Unknown(why) => format!("no interval: {}", why.phrase()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::report::compare::sides::{SideRule, sides};
    use crate::report::view::tests::measured;
    use sph_harness::results::fixtures::sweep_on;
    use sph_harness::topology::Pin;
    use sph_strategies::StrategyName::{RayonChunks, RayonIter, Seq};

    /// A sweep on the one test machine, grid rounds only, of seq (drifting by round) and,
    /// at 2 cores, rayon-chunks and rayon-iter with these walls per round.
    fn sweep(dir: &str, chunks: &[f64], iter: &[f64]) -> crate::report::load::Sweep {
        let (rows, trials) = measured(
            &[
                (Seq, 1, None, Pin::None, &[4.0, 4.4, 3.6]),
                (RayonChunks, 2, Some(4), Pin::None, chunks),
                (RayonIter, 2, None, Pin::None, iter),
            ],
            Phase::Grid,
        );
        let mut s = sweep_on(dir, "Xeon", 2, rows);
        s.trials = trials;
        s
    }

    /// 2 s and 2.4 s, drifting alike: rayon-chunks resolved faster.
    const FAST: [f64; 3] = [2.0, 2.2, 1.8];
    const SLOW: [f64; 3] = [2.4, 2.64, 2.16];

    #[test]
    fn a_ranking_resolved_one_way_and_then_the_other_is_listed_as_reversed() {
        let sweeps = [sweep("a", &FAST, &SLOW), sweep("b", &SLOW, &FAST)];
        let s = sides(&sweeps, SideRule::EachDirectory);
        let r = pairs(&s);
        assert_eq!(r.len(), 1);
        let r = &r[0];
        assert_eq!((r.cells, r.rankings, r.changed.len()), (3, 1, 1));
        // seq's speedup (a point at 1) overlaps itself; the other two are apart.
        assert_eq!(r.speedups, (1, 3));
        assert!(r.changed[0].reversed());
        let md = markdown(&pairs(&s), &["A", "B"]);
        for needle in [
            "## Reproducibility: B against A",
            "the 95 % speedup intervals overlap in 1 of 3 (33.3 %)",
            "Rankings (one strategy's best cell faster than another's at a core count, by their \
             paired rounds) resolved on either side: 1; reversed on the other: 1; resolved on \
             one side only: 0.",
            "| seed preset, all-pairs, N = 60, 3 steps | 2 | rayon-chunks | 1.20 ± 0.00× faster \
             than rayon-iter | 1.20 ± 0.00× slower than rayon-iter | **reversed** |",
        ] {
            assert!(md.contains(needle), "lacks {needle:?}:\n{md}");
        }
    }

    #[test]
    fn a_ranking_resolved_on_one_side_only_is_listed_and_a_reproduced_one_is_not() {
        let a = sweep("a", &FAST, &SLOW);
        let s = [a.clone(), sweep("b", &FAST, &SLOW)];
        let r = pairs(&sides(&s, SideRule::EachDirectory)).remove(0);
        assert_eq!((r.rankings, r.changed.len()), (1, 0));
        assert_eq!((r.speedups, r.times), ((3, 3), (3, 3)));
        let s = [a, sweep("c", &[2.0, 2.5, 1.8], &[2.1, 2.2, 2.0])];
        let r = pairs(&sides(&s, SideRule::EachDirectory)).remove(0);
        assert_eq!(r.changed.len(), 1);
        assert!(!r.changed[0].reversed());
        assert!(matches!(r.changed[0].second, Order::Unresolved(_)));
        // Two machines are compared as machines, never as a reproduction.
        let mut other = s[1].clone();
        other.meta.machine.cpu_model = "EPYC".to_owned();
        let s = [s[0].clone(), other];
        assert!(pairs(&sides(&s, SideRule::EachDirectory)).is_empty());
    }

    #[test]
    fn two_runs_on_one_machine_that_share_no_cell_say_so_in_one_sentence() {
        let a = sweep("a", &FAST, &SLOW);
        let mut b = sweep("b", &FAST, &SLOW);
        b.rows.iter_mut().for_each(|r| r.steps = 50);
        b.trials.iter_mut().for_each(|t| t.steps = 50);
        let s = [a, b];
        let r = pairs(&sides(&s, SideRule::EachDirectory));
        assert_eq!(r.len(), 1);
        assert_eq!(r[0].cells, 0);
        let md = markdown(&r, &["A", "B"]);
        assert!(md.contains("no cell was measured on both"), "{md}");
        assert!(!md.contains("none has an interval"), "{md}");
    }
}
