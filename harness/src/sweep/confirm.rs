//! The confirmation phase: which cells the grid's rounds chose, to be measured again.
//!
//! The best of many cells is biased fast when the same runs both choose it and estimate its
//! time (the winner's curse): among 20 chunk settings of equal speed, the one whose trials
//! happened to run fastest is named best, and its mean is the luckiest. So after a group's
//! grid rounds, each strategy's fastest cell per core count (and placement) — and, for a
//! strategy with chunks, the runner-up too, so the report can say whether the best chunk
//! setting beat the next — is measured again in `--confirm-rounds` shuffled rounds of its own,
//! with the group's `seq`. Only those rounds enter the findings and the best-cell tables: they
//! did not choose the cells they measure.
//!
//! A strategy whose best cell at a core count took more than [`OUT_OF_THE_RUNNING`] times the
//! fastest cell's mean there is not measured again: no timing noise turns a factor of two
//! around, so the grid's rounds settle that it lost, and its rounds are better spent on the
//! contenders (it keeps the sweep's cost within a quarter of the cell-by-cell schedule's).
//!
//! The choice is a pure function of the grid's summary rows, so a resumed sweep chooses the
//! same cells. A sharded sweep has no confirmation: a shard holds only part of each strategy's
//! cells, so its choice would not be the plan's.

use std::collections::BTreeMap;

use sph_strategies::StrategyName;

use super::plan::Plan;
use crate::results::key::Group;
use crate::results::rows::{Phase, SummaryRow};
use crate::topology::Pin;

/// How many times the fastest cell's mean at a core count a strategy's best may take and
/// still be confirmed.
pub const OUT_OF_THE_RUNNING: f64 = 2.0;

/// How a confirmed cell was chosen.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Choice {
    /// The group's `seq` reference: the partner of every paired speedup.
    Reference,
    /// The fastest cell of its strategy, core count and placement in the grid.
    Best,
    /// The second fastest, for strategies with chunks.
    RunnerUp,
}

/// The cells of `group` to confirm, as plan positions in plan order (its `seq` first), with
/// how each was chosen, from the group's grid rows in `rows`: nothing when the group's `seq`
/// did not succeed.
pub fn choose(plan: &Plan, group: &Group, rows: &[SummaryRow]) -> Vec<(usize, Choice)> {
    let usable = |r: &&SummaryRow| r.group() == *group && r.phase == Phase::Grid && r.is_usable();
    let position = |r: &SummaryRow| plan.cells.iter().position(|c| *c == r.key());
    if !rows.iter().filter(usable).any(|r| r.is_reference()) {
        return Vec::new();
    }
    // Each (strategy, cores, pin)'s usable rows with their plan positions, fastest first (the
    // plan's order between equals).
    let mut by_line: BTreeMap<(StrategyName, usize, Pin), Vec<(f64, usize)>> = BTreeMap::new();
    for r in rows.iter().filter(usable).filter(|r| !r.is_reference()) {
        if let (Some(mean), Some(at)) = (r.mean_s, position(r)) {
            by_line
                .entry((r.strategy, r.cores, r.pin))
                .or_default()
                .push((mean, at));
        }
    }
    let mut chosen: Vec<(usize, Choice)> = rows
        .iter()
        .filter(usable)
        .filter(|r| r.is_reference())
        .filter_map(|r| Some((position(r)?, Choice::Reference)))
        .collect();
    // The fastest mean at each (cores, pin), over every strategy.
    let mut fastest: BTreeMap<(usize, Pin), f64> = BTreeMap::new();
    for (&(_, cores, pin), cells) in &by_line {
        for &(mean, _) in cells {
            let f = fastest.entry((cores, pin)).or_insert(mean);
            *f = f.min(mean);
        }
    }
    for ((strategy, cores, pin), mut cells) in by_line {
        cells.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        if cells[0].0 > OUT_OF_THE_RUNNING * fastest[&(cores, pin)] {
            continue;
        }
        chosen.push((cells[0].1, Choice::Best));
        if strategy.info().uses_chunks()
            && let Some(&(_, at)) = cells.get(1)
        {
            chosen.push((at, Choice::RunnerUp));
        }
    }
    chosen.sort_by_key(|&(at, _)| at);
    chosen
}

/// How many cells [`choose`] picks for `group` of `plan` at most (for the estimate before the
/// grid has run): the reference, and per strategy, cores and placement one cell, or two for a
/// strategy with more than one chunks value.
pub fn most_chosen(plan: &Plan, group: &Group) -> usize {
    let mut lines: BTreeMap<(StrategyName, usize, Pin), usize> = BTreeMap::new();
    for c in plan.cells.iter().filter(|c| c.group == *group) {
        *lines.entry((c.strategy, c.cores, c.pin)).or_default() += 1;
    }
    lines
        .iter()
        .map(|(&(strategy, _, _), &cells)| match strategy {
            StrategyName::Seq => 1,
            s if s.info().uses_chunks() => cells.min(2),
            _ => 1,
        })
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::results::fixtures::row;
    use crate::results::params::SweepParams;
    use crate::results::rows::Status;

    fn plan() -> Plan {
        Plan::new(&SweepParams {
            strategies: vec![StrategyName::RayonIter, StrategyName::RayonChunks],
            cores: vec![1, 2],
            chunks: vec![2, 5, 10],
            ..SweepParams::small()
        })
    }

    fn rows(plan: &Plan, mean: impl Fn(usize) -> f64) -> Vec<SummaryRow> {
        plan.cells
            .iter()
            .enumerate()
            .map(|(i, c)| row(c.strategy, c.cores, c.chunks, mean(i)))
            .collect()
    }

    #[test]
    fn the_best_cell_of_each_strategy_and_cores_and_the_runner_up_with_chunks_are_chosen() {
        let plan = plan();
        let group = plan.groups[0];
        // Plan positions: seq 0, rayon-iter 1–2, rayon-chunks 3–5 (1 core: 2, 5, 10 chunks)
        // and 6–8 (2 cores). Means 1 + |position − 4| / 10: at 1 core 5 chunks is fastest and
        // 2 and 10 chunks tie (the plan's order breaks it); at 2 cores 2 chunks, then 5.
        let rows = rows(&plan, |i| 1.0 + (i as f64 - 4.0).abs() / 10.0);
        let chosen = choose(&plan, &group, &rows);
        let named: Vec<(String, Choice)> = chosen
            .iter()
            .map(|&(at, how)| (plan.cells[at].label(), how))
            .collect();
        let want = [
            ("seq, 1 core", Choice::Reference),
            ("rayon-iter, 1 core", Choice::Best),
            ("rayon-iter, 2 cores", Choice::Best),
            ("rayon-chunks, 1 core, 2 chunks", Choice::RunnerUp),
            ("rayon-chunks, 1 core, 5 chunks", Choice::Best),
            ("rayon-chunks, 2 cores, 2 chunks", Choice::Best),
            ("rayon-chunks, 2 cores, 5 chunks", Choice::RunnerUp),
        ];
        for (label, how) in want {
            assert!(
                named.iter().any(|(l, h)| l == label && *h == how),
                "{label} {how:?} not in {named:?}"
            );
        }
        assert_eq!(chosen.len(), want.len());
        assert!(chosen.windows(2).all(|w| w[0].0 < w[1].0), "plan order");
        assert_eq!(most_chosen(&plan, &group), want.len());
    }

    #[test]
    fn a_strategy_at_more_than_twice_the_fastest_time_of_its_cores_is_not_confirmed() {
        let plan = plan();
        let group = plan.groups[0];
        // rayon-iter (positions 1 and 2) twice as slow as rayon-chunks at 1 core, a hair more
        // than twice at 2 cores.
        let rows = rows(&plan, |i| match i {
            1 => 2.0,
            2 => 2.0001,
            _ => 1.0,
        });
        let chosen: Vec<usize> = choose(&plan, &group, &rows).iter().map(|c| c.0).collect();
        assert!(chosen.contains(&1) && !chosen.contains(&2), "{chosen:?}");
    }

    #[test]
    fn failed_cells_are_never_chosen_and_a_failed_seq_means_no_confirmation() {
        let plan = plan();
        let group = plan.groups[0];
        let mut rows = rows(&plan, |i| i as f64 + 1.0);
        let fastest_chunks = plan
            .cells
            .iter()
            .position(|c| c.strategy == StrategyName::RayonChunks)
            .unwrap();
        rows[fastest_chunks].status = Status::Failed;
        rows[fastest_chunks].mean_s = None;
        let chosen = choose(&plan, &group, &rows);
        assert!(chosen.iter().all(|&(at, _)| at != fastest_chunks));
        rows[0].status = Status::Failed;
        rows[0].mean_s = None;
        assert!(choose(&plan, &group, &rows).is_empty());
    }

    #[test]
    fn confirmation_rows_do_not_choose() {
        let plan = plan();
        let group = plan.groups[0];
        let mut rows = rows(&plan, |i| i as f64 + 1.0);
        for r in &mut rows {
            r.phase = Phase::Confirm;
        }
        assert!(choose(&plan, &group, &rows).is_empty());
    }
}
