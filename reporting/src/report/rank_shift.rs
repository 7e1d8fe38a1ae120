//! How the strategy ranking changes from the toy workload (a Müller preset) to the real one
//! (`wcsph`) at one core count: a [`RankShift`], decided by [`rank_shift`] from each
//! strategy's best cell, and its sentence. A change of place is stated only where both
//! orders are resolved by their own workload's paired rounds ([`order`]): the two workloads
//! ran at different times, so no number of one is set against the other's.

use sph_strategies::StrategyName;

use super::cell::Best;
use super::series;
use super::verdict::{Entry, Verdict, and_list, names, order, trusted, verdict, verdict_phrase};

/// Whether `a` is resolved faster than `b` by their paired rounds.
fn ahead(a: &Best, b: &Best) -> bool {
    matches!(order(a, b), super::verdict::Order::AFaster(_))
}

/// The ranking of the toy workload (a Müller preset) against the real one (`wcsph`) at one
/// core count, from each strategy's best cell there (see [`rank_shift`]).
#[derive(Debug, Clone, PartialEq)]
pub struct RankShift {
    /// Worker threads.
    pub cores: usize,
    /// Some cell involved had more threads than the machine.
    pub oversubscribed: bool,
    /// Contended cells left out (both workloads).
    pub contended: usize,
    /// Who is fastest on the toy workload (`None`: every cell contended).
    pub toy: Option<Verdict>,
    /// Who is fastest on wcsph.
    pub real: Option<Verdict>,
    /// Strategies that passed others on wcsph with both orders resolved, each with those it
    /// passed (in toy order).
    pub up: Vec<(StrategyName, Vec<StrategyName>)>,
    /// Strategies passed that way (in toy order).
    pub down: Vec<StrategyName>,
    /// Pairs that swap places with an order not resolved on at least one workload: (ahead on
    /// the toy workload, ahead on wcsph).
    pub unresolved: Vec<(StrategyName, StrategyName)>,
    /// Without swaps: whether every neighbouring pair's order is resolved on both.
    pub order_resolved: bool,
    /// Strategies with a trusted cell on only one workload: (toy only, wcsph only).
    pub one_sided: (Vec<StrategyName>, Vec<StrategyName>),
}

/// How the ranking at `cores` changes from the toy workload's best cells `toy` to wcsph's
/// `real` (one entry per strategy; contended cells are left out and counted).
pub fn rank_shift(cores: usize, toy: &[Entry], real: &[Entry]) -> RankShift {
    let (t, r) = (trusted(toy), trusted(real));
    let has = |v: &[Entry], s: StrategyName| v.iter().any(|(x, _)| *x == s);
    // Both orders restricted to the strategies trusted on both workloads.
    let common = |v: &[Entry], other: &[Entry]| -> Vec<Entry> {
        v.iter().filter(|(s, _)| has(other, *s)).cloned().collect()
    };
    let (ct, cr) = (common(&t, &r), common(&r, &t));
    let place = |v: &[Entry], s: StrategyName| v.iter().position(|(x, _)| *x == s);
    fn cell(v: &[Entry], s: StrategyName) -> Option<&Best> {
        v.iter().find(|(x, _)| *x == s).map(|e| &*e.1)
    }
    let (mut up, mut down, mut unresolved) = (Vec::new(), Vec::new(), Vec::new());
    for (i, (a, ta)) in ct.iter().enumerate() {
        for (b, tb) in &ct[i + 1..] {
            // a is ahead of b on the toy workload; did b pass a on wcsph?
            if place(&cr, *b) > place(&cr, *a) {
                continue;
            }
            let (Some(ra), Some(rb)) = (cell(&cr, *a), cell(&cr, *b)) else {
                continue;
            };
            if ahead(ta, tb) && ahead(rb, ra) {
                match up
                    .iter_mut()
                    .find(|(s, _): &&mut (StrategyName, Vec<_>)| s == b)
                {
                    Some((_, past)) => past.push(*a),
                    None => up.push((*b, vec![*a])),
                }
                if !down.contains(a) {
                    down.push(*a);
                }
            } else {
                unresolved.push((*a, *b));
            }
        }
    }
    let neighbours_apart = |v: &[Entry]| v.windows(2).all(|w| ahead(&w[0].1, &w[1].1));
    let only = |v: &[Entry], other: &[Entry]| -> Vec<StrategyName> {
        v.iter()
            .map(|(s, _)| *s)
            .filter(|s| !has(other, *s))
            .collect()
    };
    RankShift {
        cores,
        oversubscribed: toy.iter().chain(real).any(|(_, b)| b.oversubscribed),
        contended: (toy.len() - t.len()) + (real.len() - r.len()),
        toy: verdict(&t),
        real: verdict(&r),
        order_resolved: neighbours_apart(&ct) && neighbours_apart(&cr),
        one_sided: (only(&t, &r), only(&r, &t)),
        up,
        down,
        unresolved,
    }
}

impl RankShift {
    /// The winner on both workloads, what moved, and what the intervals do not resolve.
    pub(super) fn sentence(&self) -> String {
        let mut out = format!(
            "At {}{}, {}.",
            series::cores_label(self.cores),
            if self.oversubscribed {
                " (⚠ oversubscribed: more threads than the machine has)"
            } else {
                ""
            },
            self.winner()
        );
        if !self.up.is_empty() {
            let up: Vec<String> = self
                .up
                .iter()
                .map(|(s, past)| format!("{s} (past {})", names(past)))
                .collect();
            out.push_str(&format!(
                " Moved up on wcsph, both orders resolved by their paired rounds: {}; moved \
                 down: {}.",
                up.join(", "),
                names(&self.down)
            ));
        }
        let not_resolved = "the order not resolved by the paired rounds on at least one workload";
        match self.unresolved.len() {
            0 => {}
            // Past three swaps a list reads worse than the table beside it.
            k @ 4.. => out.push_str(&format!(
                " {k} changes of place (see the table) are not resolved, {not_resolved}."
            )),
            _ => {
                let swaps: Vec<String> = self
                    .unresolved
                    .iter()
                    .map(|(a, b)| format!("{b} now ahead of {a}"))
                    .collect();
                out.push_str(&format!(
                    " Not resolved, {not_resolved}: {}.",
                    and_list(&swaps)
                ));
            }
        }
        if self.up.is_empty() && self.unresolved.is_empty() {
            out.push_str(if self.order_resolved {
                " Every strategy measured on both keeps its place, each place resolved by the \
                 paired rounds on both workloads."
            } else {
                " Ranked by mean, every strategy measured on both keeps its place, though the \
                 paired rounds do not resolve every place."
            });
        }
        let (toy_only, real_only) = &self.one_sided;
        for (only, on) in [(toy_only, "the toy workload"), (real_only, "wcsph")] {
            if !only.is_empty() {
                out.push_str(&format!(
                    " Measured without contention on {on} only: {}.",
                    names(only)
                ));
            }
        }
        match self.contended {
            0 => {}
            1 => out.push_str(" ⚠ 1 contended cell is left out of this comparison."),
            k => out.push_str(&format!(
                " ⚠ {k} contended cells are left out of this comparison."
            )),
        }
        out
    }

    /// Whether the winner is the same, as far as the intervals tell.
    fn winner(&self) -> String {
        let fastest = |v: &Option<Verdict>| match v {
            Some(Verdict::Fastest { winner, .. }) => Some(winner.0),
            _ => None,
        };
        match (fastest(&self.toy), fastest(&self.real)) {
            (Some(a), Some(b)) if a == b => format!(
                "the winner is the same: **{a}** is fastest on both workloads, faster than \
                 every other strategy by the paired rounds on each"
            ),
            (Some(a), Some(b)) => format!(
                "the winner changes: **{a}** is fastest on the toy workload and **{b}** on \
                 wcsph, each faster than every other strategy by its own paired rounds"
            ),
            _ => format!(
                "whether the winner is the same is not resolved: on the toy workload {}; on \
                 wcsph {}",
                verdict_phrase(self.toy.as_ref()),
                verdict_phrase(self.real.as_ref())
            ),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::report::cell::{Batch, Runs};
    use sph_harness::results::fixtures::row;
    use sph_harness::results::rows::Phase;

    /// A strategy's best cell at 2 cores with these walls per round (its mean theirs), its
    /// runs paired with the other cells of its workload.
    fn entry(s: StrategyName, walls: &[f64]) -> Entry {
        let mean = walls.iter().sum::<f64>() / walls.len() as f64;
        let runs = Runs {
            batch: Batch {
                source: 0,
                phase: Phase::Grid,
                shard: None,
                paired: true,
            },
            rounds: walls
                .iter()
                .copied()
                .enumerate()
                .map(|(i, w)| (i + 1, w))
                .collect(),
        };
        (s, Box::new(Best::of(&row(s, 2, None, mean), runs).unwrap()))
    }

    /// `mean` times the same drift in every strategy: orders between these are resolved.
    fn steady(s: StrategyName, mean: f64) -> Entry {
        entry(s, &[mean, mean * 1.05, mean * 0.95])
    }

    fn shift(toy: &[Entry], real: &[Entry]) -> String {
        rank_shift(2, toy, real).sentence()
    }

    #[test]
    fn a_ranking_resolved_on_both_workloads_names_the_same_winner() {
        use StrategyName::{RayonChunks, RayonIter};
        let toy = [steady(RayonChunks, 2.0), steady(RayonIter, 2.6)];
        let real = [steady(RayonIter, 3.0), steady(RayonChunks, 2.5)];
        assert_eq!(
            shift(&toy, &real),
            "At 2 cores, the winner is the same: **rayon-chunks** is fastest on both workloads, \
             faster than every other strategy by the paired rounds on each. Every strategy \
             measured on both keeps its place, each place resolved by the paired rounds on both \
             workloads."
        );
    }

    #[test]
    fn a_strategy_that_passes_another_with_both_orders_resolved_moved_up_and_the_other_down() {
        use StrategyName::{CrossbeamPool, RayonChunks, RayonIter, StdStatic};
        let toy = [
            steady(RayonChunks, 1.0),
            steady(CrossbeamPool, 1.1),
            steady(RayonIter, 1.2),
            steady(StdStatic, 1.3),
        ];
        // On wcsph std-static passes crossbeam-pool and rayon-iter; rayon-iter passes
        // crossbeam-pool, but their rounds disagree.
        let real = [
            steady(RayonChunks, 1.0),
            steady(StdStatic, 1.05),
            steady(RayonIter, 1.2),
            entry(CrossbeamPool, &[1.21, 1.24, 1.18]),
        ];
        let f = shift(&toy, &real);
        assert!(
            f.starts_with("At 2 cores, the winner is the same: **rayon-chunks**"),
            "{f}"
        );
        assert!(
            f.contains(
                "Moved up on wcsph, both orders resolved by their paired rounds: std-static \
                 (past crossbeam-pool and rayon-iter); moved down: crossbeam-pool and \
                 rayon-iter."
            ),
            "{f}"
        );
        assert!(
            f.contains(
                "Not resolved, the order not resolved by the paired rounds on at least one \
                 workload: rayon-iter now ahead of crossbeam-pool."
            ),
            "{f}"
        );
    }

    #[test]
    fn rounds_that_disagree_leave_the_winner_and_the_swap_unresolved() {
        use StrategyName::{RayonChunks, RayonIter};
        let toy = [
            entry(RayonChunks, &[2.0, 2.4, 1.6]),
            entry(RayonIter, &[2.1, 2.2, 1.9]),
        ];
        let real = [steady(RayonIter, 2.0), steady(RayonChunks, 2.5)];
        let f = shift(&toy, &real);
        assert!(
            f.starts_with(
                "At 2 cores, whether the winner is the same is not resolved: on the toy \
                 workload rayon-chunks and rayon-iter are not distinguishable by their paired \
                 rounds; on wcsph **rayon-iter** is fastest."
            ),
            "{f}"
        );
        assert!(f.contains("rayon-iter now ahead of rayon-chunks"), "{f}");
        assert!(!f.contains("Moved up"), "{f}");
    }

    #[test]
    fn contended_and_oversubscribed_cells_are_named_as_caveats_and_left_out() {
        use StrategyName::{RayonChunks, RayonIter, StdStatic};
        let mut noisy = steady(StdStatic, 0.5);
        noisy.1.contended = true;
        let mut over = steady(RayonIter, 2.6);
        over.1.oversubscribed = true;
        let toy = [noisy, steady(RayonChunks, 2.0), over];
        let real = [steady(RayonChunks, 2.0), steady(StdStatic, 2.2)];
        let f = shift(&toy, &real);
        assert!(
            f.starts_with(
                "At 2 cores (⚠ oversubscribed: more threads than the machine has), the winner \
                 is the same: **rayon-chunks**"
            ),
            "{f}"
        );
        assert!(
            f.contains("Measured without contention on the toy workload only: rayon-iter."),
            "{f}"
        );
        assert!(
            f.contains("Measured without contention on wcsph only: std-static."),
            "{f}"
        );
        assert!(
            f.ends_with("⚠ 1 contended cell is left out of this comparison."),
            "{f}"
        );
    }

    #[test]
    fn without_intervals_no_winner_and_no_move_is_claimed() {
        use StrategyName::{RayonChunks, RayonIter};
        let toy = [
            entry(RayonChunks, &[2.0, 2.0]),
            entry(RayonIter, &[2.6, 2.6]),
        ];
        let real = [
            entry(RayonIter, &[2.0, 2.0]),
            entry(RayonChunks, &[2.6, 2.6]),
        ];
        let f = shift(&toy, &real);
        assert!(
            f.contains(
                "on the toy workload the lowest mean is rayon-chunks's, but with only 2 paired \
                 rounds in common (3 are needed for an interval), so no strategy can be called \
                 fastest"
            ),
            "{f}"
        );
        assert!(!f.contains("Moved up") && f.contains("Not resolved"), "{f}");
    }
}
