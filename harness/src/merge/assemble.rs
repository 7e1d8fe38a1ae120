//! Putting one plan's cells together from its shards (pure: rows in, rows out).
//!
//! Every cell of the whole plan is taken from the shard that ran it. A group's `seq` cell was
//! measured by every shard that has the group: the merged `summary.csv` takes the one of the
//! lowest-numbered shard (the cell set is then exactly the unsharded plan's), and
//! `references.csv` keeps every shard's. Each row keeps the speedup its own shard computed
//! against its own `seq` (`reference_shard`), so no speedup divides times from two nodes.
//!
//! A shard whose `seq` cell of a group was left out as unusable ([`Unreferenced`]) has no
//! denominator for its other cells of that group: the merge refuses it unless
//! `--allow-partial`, and then those cells keep their times but lose their speedup and
//! efficiency, and `references.csv` holds that shard's `seq` as a failed row saying why.

use std::collections::{HashMap, HashSet};

use anyhow::bail;

use crate::output::digits::sig;
use crate::results::key::{Cell, Group, LabelStyle};
use crate::results::load::Dropped;
use crate::results::rows::{Phase, SummaryRow, TrialRow};
use crate::results::shard::Shard;
use crate::results::summarize::{CellContext, summary_row};
use crate::sweep::Plan;

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
    /// Its cells left out as unusable, each with why.
    pub dropped: Vec<Dropped>,
}

/// A group of a shard whose `seq` reference cell was left out (see the module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct Unreferenced {
    /// The shard.
    pub shard: Shard,
    /// Its directory, as given.
    pub dir: String,
    /// The group.
    pub group: Group,
    /// Why its `seq` cell is unusable.
    pub why: String,
    /// The shard's other cells of the group, in the merge without a speedup.
    pub cells: Vec<Cell>,
}

impl Unreferenced {
    /// One line saying what happened (without what to do, which depends on the caller).
    pub fn describe(&self) -> String {
        format!(
            "'{}' (shard {}): its seq reference of {} is unusable ({}), so its {} of that \
             group {} no speedup",
            self.dir,
            self.shard,
            self.group.label(LabelStyle::Sweep),
            self.why,
            crate::output::console::plural(self.cells.len(), "other cell", "other cells"),
            if self.cells.len() == 1 { "has" } else { "have" }
        )
    }
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
    /// The shards' groups whose `seq` was left out: their cells are in `summary` without a
    /// speedup, and the `seq` in `references` as a failed row.
    pub unreferenced: Vec<Unreferenced>,
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
                    "'{}': the row of {} has reference_shard {}, not {}: was summary.csv \
                     edited? Restore it, or run the shard again",
                    part.dir,
                    row.key().label_with_group(),
                    row.reference_shard
                        .map_or_else(|| "empty".to_owned(), |s| s.to_string()),
                    part.shard.index
                );
            }
        }
    }
    let unreferenced: Vec<Unreferenced> = sorted
        .iter()
        .flat_map(|part| whole.groups.iter().filter_map(|g| without_its_seq(part, g)))
        .collect();
    let without_seq = |part: &Part, group: &Group| {
        unreferenced
            .iter()
            .any(|u| u.shard == part.shard && u.group == *group)
    };
    let row_of = |part: &Part, cell: &Cell| part.rows.iter().find(|r| r.key() == *cell).cloned();
    let mut out = Assembled {
        summary: Vec::new(),
        trials: Vec::new(),
        references: Vec::new(),
        missing: Vec::new(),
        cells_from: HashMap::new(),
        disagreements: Vec::new(),
        unreferenced: Vec::new(),
    };
    for cell in &whole.cells {
        let candidates: Vec<(&Part, SummaryRow)> = sorted
            .iter()
            .filter_map(|p| row_of(p, cell).map(|r| (*p, r)))
            .collect();
        if cell.is_reference() {
            for part in &sorted {
                match candidates.iter().find(|(p, _)| p.shard == part.shard) {
                    Some((_, row)) => out.references.push(row.clone()),
                    None if without_seq(part, &cell.group) => {
                        out.references
                            .push(failed_reference(part, cell, &unreferenced));
                    }
                    None => {}
                }
            }
            if let Some(line) = disagreement(&cell.group, &candidates) {
                out.disagreements.push(line);
            }
        }
        // Outside the references, at most one shard can hold a cell (checked above).
        match candidates.first() {
            Some((part, row)) => {
                let mut row = row.clone();
                if without_seq(part, &cell.group) {
                    // No denominator: never a speedup against another node's seq.
                    row.speedup = None;
                    row.efficiency = None;
                    row.speedup_ci_low = None;
                    row.speedup_ci_high = None;
                }
                *out.cells_from.entry(part.shard.index).or_default() += 1;
                let mut trials: Vec<TrialRow> = part
                    .trials
                    .iter()
                    .filter(|t| t.key() == *cell)
                    .cloned()
                    .collect();
                trials.sort_by_key(|t| t.trial);
                out.trials.extend(trials);
                out.summary.push(row);
            }
            None => out.missing.push(*cell),
        }
    }
    out.unreferenced = unreferenced;
    Ok(out)
}

/// The group `group` of `part`, if the part holds cells of it but no usable `seq` cell.
fn without_its_seq(part: &Part, group: &Group) -> Option<Unreferenced> {
    let of_group = || part.rows.iter().filter(|r| r.group() == *group);
    if of_group().any(|r| r.is_reference()) {
        return None;
    }
    let cells: Vec<Cell> = of_group().map(SummaryRow::key).collect();
    if cells.is_empty() {
        return None;
    }
    let seq = Cell::reference(*group);
    let why = part
        .dropped
        .iter()
        .find(|d| d.cell == seq && d.phase == Phase::Grid)
        .map_or_else(
            || "its row in summary.csv is missing or unreadable".to_owned(),
            |d| d.why.clone(),
        );
    Some(Unreferenced {
        shard: part.shard,
        dir: part.dir.clone(),
        group: *group,
        why,
        cells,
    })
}

/// The row `references.csv` holds for `part`'s unusable `seq` cell `seq`: failed, no numbers,
/// the reason saying why.
fn failed_reference(part: &Part, seq: &Cell, unreferenced: &[Unreferenced]) -> SummaryRow {
    let why = unreferenced
        .iter()
        .find(|u| u.shard == part.shard && u.group == seq.group)
        .map_or("", |u| u.why.as_str());
    let ctx = CellContext {
        hardware_threads: 1,
        shard: Some(part.shard.index),
        smt: None,
    };
    let reason = format!("left out by bench-sph merge: {why}");
    summary_row(seq, Phase::Grid, &[], None, Some(&reason), &ctx)
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
    use sph_solver::sph::neighbors::NeighborMode;
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
                let mut r = crate::results::fixtures::row(c.strategy, c.cores, c.chunks, mean);
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
            dropped: Vec::new(),
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
    fn a_shard_without_its_seq_keeps_its_cells_without_a_speedup_and_a_failed_reference() {
        let whole = Plan::new(&params());
        let mut parts: Vec<Part> = (1..=3).map(|i| part(&whole, i, 3, 4.0)).collect();
        let seq = parts[2].rows.remove(0);
        assert!(seq.is_reference());
        parts[2].dropped.push(Dropped {
            cell: seq.key(),
            phase: Phase::Grid,
            why: "trial 1: wall_s = NaN is not a positive time".to_owned(),
        });
        let merged = assemble(&whole, &parts).unwrap();
        assert!(merged.missing.is_empty());
        assert_eq!(merged.unreferenced.len(), 1);
        let u = &merged.unreferenced[0];
        assert_eq!((u.shard.index, u.cells.len()), (3, parts[2].rows.len()));
        assert!(
            u.describe().contains("is unusable (trial 1: wall_s = NaN"),
            "{u:?}"
        );
        for r in merged
            .summary
            .iter()
            .filter(|r| r.reference_shard == Some(3))
        {
            assert_eq!(
                (r.speedup, r.efficiency, r.speedup_ci_low),
                (None, None, None)
            );
            assert!(r.mean_s.is_some());
        }
        let refs: Vec<(Option<usize>, Status)> = merged
            .references
            .iter()
            .map(|r| (r.reference_shard, r.status))
            .collect();
        assert_eq!(
            refs,
            [
                (Some(1), Status::Ok),
                (Some(2), Status::Ok),
                (Some(3), Status::Failed)
            ]
        );
        assert!(merged.references[2].reason.contains("wall_s = NaN"));
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
