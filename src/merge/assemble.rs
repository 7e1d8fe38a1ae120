//! Putting one plan's cells together from its shards (pure: rows in, rows out).
//!
//! Every cell of the whole plan is taken from the shard that ran it. A group's `seq` cell was
//! measured by every shard that has the group: the merged `summary.csv` takes the one of the
//! lowest-numbered shard (the cell set is then exactly the unsharded plan's), and
//! `references.csv` keeps every shard's. Each row keeps the speedup its own shard computed
//! against its own `seq` (`reference_shard`), so no speedup divides times from two nodes.

use std::collections::{HashMap, HashSet};

use anyhow::bail;

use crate::report::numbers::sig;
use crate::results::key::{Cell, Group, LabelStyle};
use crate::results::rows::{SummaryRow, TrialRow};
use crate::results::shard::Shard;
use crate::sweep::plan::Plan;

/// One shard's believed cells.
#[derive(Debug, Clone)]
pub struct Part {
    /// Which shard.
    pub shard: Shard,
    /// Its directory, as given (for messages).
    pub dir: String,
    /// Its finished cells' summary rows.
    pub rows: Vec<SummaryRow>,
    /// Their trial rows.
    pub trials: Vec<TrialRow>,
}

/// The merged study.
#[derive(Debug, Clone, PartialEq)]
pub struct Assembled {
    /// One row per cell of the whole plan that some shard has, in plan order.
    pub summary: Vec<SummaryRow>,
    /// Their trial rows, in the same order.
    pub trials: Vec<TrialRow>,
    /// Every shard's `seq` rows, by group, then shard.
    pub references: Vec<SummaryRow>,
    /// Cells of the whole plan no shard has, in plan order.
    pub missing: Vec<Cell>,
    /// Cells in the merge per shard number.
    pub cells_from: HashMap<usize, usize>,
    /// One line per group whose shards' `seq` means disagree beyond their intervals.
    pub disagreements: Vec<String>,
}

/// The merge of `parts` (shards of `whole`, already checked to be of one plan, build and
/// machine); an error if a shard holds a cell that is not in its part of the plan.
pub fn assemble(whole: &Plan, parts: &[Part]) -> anyhow::Result<Assembled> {
    let mut sorted: Vec<&Part> = parts.iter().collect();
    sorted.sort_by_key(|p| p.shard.index);
    for part in &sorted {
        let expected: HashSet<Cell> = whole.shard(part.shard).cells.into_iter().collect();
        for row in &part.rows {
            if row.phase != crate::results::rows::Phase::Grid {
                bail!(
                    "'{}' holds confirmation rows ({}): a shard has none, so it is not a \
                     shard of this plan as `sweep --shard` writes it",
                    part.dir,
                    row.key().label_with_group()
                );
            }
            if !expected.contains(&row.key()) {
                bail!(
                    "'{}' holds {}, which is not a cell of shard {} of this plan",
                    part.dir,
                    row.key().label_with_group(),
                    part.shard
                );
            }
            if row.reference_shard != Some(part.shard.index) {
                bail!(
                    "'{}': the row of {} has reference_shard {:?}, not {}: was summary.csv \
                     edited?",
                    part.dir,
                    row.key().label_with_group(),
                    row.reference_shard,
                    part.shard.index
                );
            }
        }
    }
    let row_of = |part: &Part, cell: &Cell| part.rows.iter().find(|r| r.key() == *cell).cloned();
    let mut out = Assembled {
        summary: Vec::new(),
        trials: Vec::new(),
        references: Vec::new(),
        missing: Vec::new(),
        cells_from: HashMap::new(),
        disagreements: Vec::new(),
    };
    for cell in &whole.cells {
        let candidates: Vec<(&Part, SummaryRow)> = sorted
            .iter()
            .filter_map(|p| row_of(p, cell).map(|r| (*p, r)))
            .collect();
        if cell.is_reference() {
            out.references
                .extend(candidates.iter().map(|(_, r)| r.clone()));
            if let Some(line) = disagreement(&cell.group, &candidates) {
                out.disagreements.push(line);
            }
        }
        // Outside the references, at most one shard can hold a cell (checked above).
        match candidates.first() {
            Some((part, row)) => {
                *out.cells_from.entry(part.shard.index).or_default() += 1;
                let mut trials: Vec<TrialRow> = part
                    .trials
                    .iter()
                    .filter(|t| t.key() == *cell)
                    .cloned()
                    .collect();
                trials.sort_by_key(|t| t.trial);
                out.trials.extend(trials);
                out.summary.push(row.clone());
            }
            None => out.missing.push(*cell),
        }
    }
    Ok(out)
}

/// A warning when two shards' `seq` means of `group` have disjoint 95 % intervals: the nodes
/// are not as identical as claimed, or one was disturbed.
fn disagreement(group: &Group, seqs: &[(&Part, SummaryRow)]) -> Option<String> {
    let interval = |r: &SummaryRow| Some((r.mean_ci_low_s?, r.mean_ci_high_s?));
    let with: Vec<(usize, f64, (f64, f64))> = seqs
        .iter()
        .filter_map(|(p, r)| Some((p.shard.index, r.mean_s?, interval(r)?)))
        .collect();
    let apart = with.iter().any(|(_, _, (lo_a, hi_a))| {
        with.iter()
            .any(|(_, _, (lo_b, hi_b))| hi_a < lo_b || hi_b < lo_a)
    });
    if !apart {
        return None;
    }
    let each: Vec<String> = with
        .iter()
        .map(|(s, mean, (lo, hi))| {
            format!("shard {s}: {} s [{}–{}]", sig(*mean), sig(*lo), sig(*hi))
        })
        .collect();
    Some(format!(
        "{}: the shards' seq means disagree beyond their 95 % intervals ({}): the nodes may not \
         be as identical as claimed, or one was busy; each speedup divides by its own shard's \
         seq (reference_shard)",
        group.label(LabelStyle::Sweep),
        each.join("; ")
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::results::params::SweepParams;
    use crate::results::rows::Status;
    use crate::sph::neighbors::NeighborMode;
    use sph_strategies::StrategyName;

    fn params() -> SweepParams {
        SweepParams {
            strategies: vec![StrategyName::RayonChunks, StrategyName::StdStatic],
            neighbors: vec![NeighborMode::Grid],
            ..SweepParams::small()
        }
    }

    /// A shard's part with every cell it should have, `seq` taking `seq_s` seconds.
    fn part(whole: &Plan, index: usize, count: usize, seq_s: f64) -> Part {
        let shard = Shard::new(index, count).unwrap();
        let cells = whole.shard(shard).cells;
        let rows: Vec<SummaryRow> = cells
            .iter()
            .map(|c| {
                let mean = if c.is_reference() { seq_s } else { 1.0 };
                let mut r = crate::results::rows::tests::row(c.strategy, c.cores, c.chunks, mean);
                (r.preset, r.neighbors, r.n, r.steps) =
                    (c.group.preset, c.group.neighbors, c.group.n, c.group.steps);
                r.reference_shard = Some(index);
                r
            })
            .collect();
        let trials = rows
            .iter()
            .flat_map(|r| {
                (1..=r.trials).map(|t| TrialRow {
                    strategy: r.strategy,
                    neighbors: r.neighbors,
                    preset: r.preset,
                    n: r.n,
                    steps: r.steps,
                    cores: r.cores,
                    chunks: r.chunks,
                    particles_per_chunk: r.particles_per_chunk,
                    trial: t,
                    wall_s: 1.0,
                    cpu_s: 1.0,
                    checksum: r.checksum.clone(),
                    status: Status::Ok,
                    reason: String::new(),
                    foreign_cpu_s: None,
                    steal_s: None,
                    load1: None,
                    pin: r.pin,
                    phase: r.phase,
                    round: Some(t),
                    position: Some(1),
                    window_foreign_threads: None,
                    contended: None,
                })
            })
            .collect();
        Part {
            shard,
            dir: format!("shard-{index}"),
            rows,
            trials,
        }
    }

    #[test]
    fn three_shards_merge_into_exactly_the_cells_of_the_whole_plan_with_one_seq() {
        let whole = Plan::new(&params());
        let parts: Vec<Part> = (1..=3).map(|i| part(&whole, i, 3, 4.0)).collect();
        let merged = assemble(&whole, &parts).unwrap();
        let keys: Vec<Cell> = merged.summary.iter().map(SummaryRow::key).collect();
        assert_eq!(keys, whole.cells);
        assert!(merged.missing.is_empty());
        assert_eq!(merged.references.len(), 3, "every shard has the one group");
        assert_eq!(merged.summary[0].reference_shard, Some(1));
        assert_eq!(merged.trials.len(), whole.cells.len() * 3);
        assert_eq!(merged.cells_from.values().sum::<usize>(), whole.cells.len());
        assert!(merged.disagreements.is_empty());
    }

    #[test]
    fn a_missing_shard_leaves_its_cells_missing_and_disjoint_seq_intervals_are_named() {
        let whole = Plan::new(&params());
        let parts = vec![part(&whole, 1, 3, 4.0), part(&whole, 3, 3, 5.0)];
        let merged = assemble(&whole, &parts).unwrap();
        let two = whole.shard(Shard::new(2, 3).unwrap()).non_reference_cells();
        assert_eq!(merged.missing.len(), two);
        assert_eq!(merged.disagreements.len(), 1);
        let line = &merged.disagreements[0];
        assert!(
            line.contains("shard 1: 4.00 s [3.92–4.08]") && line.contains("shard 3: 5.00 s"),
            "{line}"
        );
    }

    #[test]
    fn a_cell_outside_its_shards_part_or_of_another_shard_is_refused() {
        let whole = Plan::new(&params());
        let mut one = part(&whole, 1, 3, 4.0);
        let two = part(&whole, 2, 3, 4.0);
        one.rows.push(two.rows.last().unwrap().clone());
        let err = assemble(&whole, &[one, two]).unwrap_err().to_string();
        assert!(err.contains("not a cell of shard 1/3"), "{err}");
        let mut one = part(&whole, 1, 3, 4.0);
        one.rows[1].reference_shard = Some(2);
        let err = assemble(&whole, &[one]).unwrap_err().to_string();
        assert!(err.contains("reference_shard"), "{err}");
    }
}
