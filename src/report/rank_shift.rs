//! How the strategy ranking changes from the toy workload (a Müller preset) to the real one
//! (`wcsph`) at one core count: a [`RankShift`], decided by [`rank_shift`] from each
//! strategy's best cell, and its sentence. A change of place is stated only where the 95 %
//! intervals are apart on both workloads.

use sph_strategies::StrategyName;

use super::findings::{Entry, Verdict, and_list, apart, names, trusted, verdict, verdict_phrase};
use super::series::{self, Best};

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
    /// Strategies that passed others on wcsph with the intervals apart on both workloads,
    /// each with those it passed (in toy order).
    pub up: Vec<(StrategyName, Vec<StrategyName>)>,
    /// Strategies passed that way (in toy order).
    pub down: Vec<StrategyName>,
    /// Pairs that swap places with overlapping (or missing) intervals on at least one
    /// workload: (ahead on the toy workload, ahead on wcsph).
    pub unresolved: Vec<(StrategyName, StrategyName)>,
    /// Without swaps: whether every neighbouring pair's intervals are apart on both.
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
        v.iter().find(|(x, _)| *x == s).map(|e| &e.1)
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
            if apart(ta, tb) && apart(ra, rb) {
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
    let neighbours_apart = |v: &[Entry]| v.windows(2).all(|w| apart(&w[0].1, &w[1].1));
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
                " Moved up on wcsph, with the 95 % intervals apart on both workloads: {}; \
                 moved down: {}.",
                up.join(", "),
                names(&self.down)
            ));
        }
        let not_resolved = "the 95 % intervals overlapping (or missing) on at least one workload";
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
                " Every strategy measured on both keeps its place, with the 95 % intervals \
                 apart on both workloads."
            } else {
                " Ranked by mean, every strategy measured on both keeps its place, though the \
                 95 % intervals do not resolve every place."
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
                "the winner is the same: **{a}** is fastest on both workloads, its 95 % \
                 interval apart from every other strategy's on each"
            ),
            (Some(a), Some(b)) => format!(
                "the winner changes: **{a}** is fastest on the toy workload and **{b}** on \
                 wcsph, each with its 95 % interval apart from every other strategy's"
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
    use crate::report::findings::Finding;
    use crate::report::findings::tests::with_ci;
    use crate::results::rows::tests::row;

    /// A strategy's best cell at 2 cores: `mean` seconds, its interval `mean ± half`.
    fn entry(s: StrategyName, mean: f64, half: f64) -> Entry {
        let r = with_ci(row(s, 2, None, mean), mean - half, mean + half);
        (
            s,
            series::best_per_cores(
                std::slice::from_ref(&r),
                &r.group(),
                series::SeriesKey::unpinned(s),
            )
            .remove(0),
        )
    }

    fn shift(toy: &[Entry], real: &[Entry]) -> String {
        Finding::RankShift(Box::new(rank_shift(2, toy, real))).sentence()
    }

    #[test]
    fn a_ranking_that_holds_with_intervals_apart_names_the_same_winner() {
        use StrategyName::{RayonChunks, RayonIter};
        let toy = [entry(RayonChunks, 2.0, 0.05), entry(RayonIter, 2.6, 0.05)];
        let real = [entry(RayonIter, 3.0, 0.05), entry(RayonChunks, 2.5, 0.05)];
        assert_eq!(
            shift(&toy, &real),
            "At 2 cores, the winner is the same: **rayon-chunks** is fastest on both workloads, \
             its 95 % interval apart from every other strategy's on each. Every strategy \
             measured on both keeps its place, with the 95 % intervals apart on both workloads."
        );
    }

    #[test]
    fn a_strategy_that_passes_another_beyond_the_intervals_moved_up_and_the_other_down() {
        use StrategyName::{CrossbeamPool, RayonChunks, RayonIter, StdStatic};
        let toy = [
            entry(RayonChunks, 1.0, 0.01),
            entry(CrossbeamPool, 1.1, 0.01),
            entry(RayonIter, 1.2, 0.01),
            entry(StdStatic, 1.3, 0.01),
        ];
        // On wcsph std-static passes crossbeam-pool and rayon-iter; rayon-iter passes
        // crossbeam-pool within the intervals only.
        let real = [
            entry(RayonChunks, 1.0, 0.01),
            entry(StdStatic, 1.05, 0.01),
            entry(RayonIter, 1.2, 0.03),
            entry(CrossbeamPool, 1.21, 0.03),
        ];
        let f = shift(&toy, &real);
        assert!(
            f.starts_with("At 2 cores, the winner is the same: **rayon-chunks**"),
            "{f}"
        );
        assert!(
            f.contains(
                "Moved up on wcsph, with the 95 % intervals apart on both workloads: std-static \
                 (past crossbeam-pool and rayon-iter); moved down: crossbeam-pool and rayon-iter."
            ),
            "{f}"
        );
        assert!(
            f.contains(
                "Not resolved, the 95 % intervals overlapping (or missing) on at least one \
                 workload: rayon-iter now ahead of crossbeam-pool."
            ),
            "{f}"
        );
    }

    #[test]
    fn overlapping_intervals_leave_the_winner_and_the_swap_unresolved() {
        use StrategyName::{RayonChunks, RayonIter};
        let toy = [entry(RayonChunks, 2.0, 0.2), entry(RayonIter, 2.1, 0.2)];
        let real = [entry(RayonIter, 2.0, 0.05), entry(RayonChunks, 2.5, 0.05)];
        let f = shift(&toy, &real);
        assert!(
            f.starts_with(
                "At 2 cores, whether the winner is the same is not resolved: on the toy \
                 workload rayon-chunks and rayon-iter are indistinguishable within the trial \
                 spread (their 95 % intervals overlap); on wcsph **rayon-iter** is fastest."
            ),
            "{f}"
        );
        assert!(f.contains("rayon-iter now ahead of rayon-chunks"), "{f}");
        assert!(!f.contains("Moved up"), "{f}");
    }

    #[test]
    fn contended_and_oversubscribed_cells_are_named_as_caveats_and_left_out() {
        use StrategyName::{RayonChunks, RayonIter, StdStatic};
        let mut noisy = entry(StdStatic, 0.5, 0.01);
        noisy.1.contended = true;
        let mut over = entry(RayonIter, 2.6, 0.05);
        over.1.oversubscribed = true;
        let toy = [noisy, entry(RayonChunks, 2.0, 0.05), over];
        let real = [entry(RayonChunks, 2.0, 0.05), entry(StdStatic, 2.2, 0.05)];
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
        let bare = |s, mean| {
            let mut e = entry(s, mean, 0.0);
            e.1.mean_ci = None;
            e
        };
        let toy = [bare(RayonChunks, 2.0), bare(RayonIter, 2.6)];
        let real = [bare(RayonIter, 2.0), bare(RayonChunks, 2.6)];
        let f = shift(&toy, &real);
        assert!(
            f.contains(
                "on the toy workload the lowest mean is rayon-chunks's, but without \
                        confidence intervals no strategy can be called fastest"
            ),
            "{f}"
        );
        assert!(!f.contains("Moved up") && f.contains("Not resolved"), "{f}");
    }
}
