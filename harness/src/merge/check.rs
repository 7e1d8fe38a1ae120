//! The refusals of `bench-sph merge`, as pure functions of the shards' `meta.json`: only the
//! shards of one plan, written by a sweep and measured by one build on one kind of machine,
//! merge; and the check of each shard's cells against its plan ([`against_plan`]).

use std::collections::HashMap;

use anyhow::bail;

use crate::results::meta::{Meta, SWEEP_TOOL};
use crate::results::params::SweepParams;
use crate::results::rows::{Phase, Status, SummaryRow, TrialRow};
use crate::results::shard::Shard;
use crate::sweep::Plan;

/// A shard directory's `meta.json`, with where it was read from.
#[derive(Debug, Clone)]
pub struct ShardMeta<'a> {
    /// The directory, as given.
    pub dir: String,
    /// Its `meta.json`.
    pub meta: &'a Meta,
}

/// The shard each directory holds, once all of them are shards of one plan, build and machine;
/// otherwise the first reason they are not.
pub fn shards(parts: &[ShardMeta<'_>]) -> anyhow::Result<Vec<Shard>> {
    let Some(first) = parts.first() else {
        bail!("no shard directory given");
    };
    let mut shards = Vec::new();
    for p in parts {
        if p.meta.tool != SWEEP_TOOL {
            bail!(
                "'{}' was written by `{}`, not by `{SWEEP_TOOL}` (its meta.json's tool): only \
                 the directories of `bench-sph sweep --shard I/K` merge",
                p.dir,
                p.meta.tool
            );
        }
        if p.meta.merge.is_some() {
            bail!(
                "'{}' is already a merge of shards: merge the shard directories themselves",
                p.dir
            );
        }
        let Some(shard) = p.meta.params.shard else {
            bail!(
                "'{}' is not a shard (its meta.json names no --shard): only the directories of \
                 `bench-sph sweep --shard I/K` merge",
                p.dir
            );
        };
        shards.push(shard);
    }
    let first_shard = shards[0];
    for (p, s) in parts.iter().zip(&shards) {
        if s.count != first_shard.count {
            bail!(
                "'{}' (shard {s}) and '{}' (shard {first_shard}) are shards of different splits \
                 ({} of {} and {} of {}): merge the shards of one split, all run with the same \
                 `--shard I/{}`",
                p.dir,
                first.dir,
                s.index,
                s.count,
                first_shard.index,
                first_shard.count,
                first_shard.count
            );
        }
    }
    let mut seen: HashMap<usize, &str> = HashMap::new();
    for (p, s) in parts.iter().zip(&shards) {
        if let Some(other) = seen.insert(s.index, &p.dir) {
            bail!(
                "shard {s} is given twice ('{other}' and '{}'): each cell must count once; give \
                 each shard's directory once",
                p.dir
            );
        }
    }
    same_plan(parts)?;
    planned_cells(parts)?;
    same_build(parts)?;
    same_machine(parts)?;
    Ok(shards)
}

/// Every shard has the first's plan fingerprint, and its recorded one is its own.
fn same_plan(parts: &[ShardMeta<'_>]) -> anyhow::Result<()> {
    let first = &parts[0];
    let want = first.meta.params.fingerprint();
    for p in parts {
        let got = p.meta.params.fingerprint();
        if p.meta.plan_fingerprint.as_ref().is_some_and(|f| *f != got) {
            bail!(
                "'{}': its meta.json records plan {} but its parameters are those of plan {got}: \
                 was it edited?",
                p.dir,
                p.meta.plan_fingerprint.as_deref().unwrap_or_default()
            );
        }
        if got != want {
            bail!(
                "'{}' (plan {got}) and '{}' (plan {want}) are shards of different plans: their \
                 parameters differ (compare the `params` of their meta.json)",
                p.dir,
                first.dir
            );
        }
    }
    Ok(())
}

/// Every shard's `planned_cells` is the number of cells its parameters plan.
fn planned_cells(parts: &[ShardMeta<'_>]) -> anyhow::Result<()> {
    for p in parts {
        let planned = Plan::new(&p.meta.params).cells.len();
        if p.meta.planned_cells != planned {
            bail!(
                "'{}': its meta.json says planned_cells = {} but its parameters plan {}: was \
                 it edited? Restore it, or run the shard again",
                p.dir,
                p.meta.planned_cells,
                crate::output::console::plural(planned, "cell", "cells")
            );
        }
    }
    Ok(())
}

/// Why a shard's cell (its summary row and its trial rows, in trial order) does not have the
/// numbers of trials and rounds its plan (`params`) gives it, or `Ok`: an ok cell ran every
/// round of the grid, a failed one at most that many, and every run names a round of the
/// plan. (Confirmation rows are refused whole by [`super::assemble`].)
pub fn against_plan(
    row: &SummaryRow,
    trials: &[TrialRow],
    params: &SweepParams,
) -> Result<(), String> {
    let rounds = params.trials;
    if row.phase != Phase::Grid {
        return Ok(());
    }
    let plural = |k| crate::output::console::plural(k, "trial", "trials");
    if row.status == Status::Ok && row.trials != rounds {
        return Err(format!(
            "an ok cell of {}, but its plan runs {} (--trials {rounds})",
            plural(row.trials),
            crate::output::console::plural(rounds, "round", "rounds")
        ));
    }
    if row.trials > rounds {
        return Err(format!(
            "{}, but its plan runs {} (--trials {rounds})",
            plural(row.trials),
            crate::output::console::plural(rounds, "round", "rounds")
        ));
    }
    for t in trials {
        if let Some(r) = t.round
            && !(1..=rounds).contains(&r)
        {
            return Err(format!(
                "trial {}: round {r} is not one of its plan's rounds 1 to {rounds}",
                t.trial
            ));
        }
    }
    Ok(())
}

/// Every session of every shard ran the first shard's version, commit and compiler.
fn same_build(parts: &[ShardMeta<'_>]) -> anyhow::Result<()> {
    let first = &parts[0];
    let build = |m: &Meta| (m.version.clone(), m.git_commit.clone(), m.rustc.clone());
    let want = build(first.meta);
    for p in parts {
        let commits = std::iter::once(p.meta.git_commit.as_str())
            .chain(p.meta.sessions.iter().map(|s| s.git_commit.as_str()));
        if let Some(other) = commits.into_iter().find(|&c| c != want.1) {
            bail!(
                "'{}' was measured with bench-sph {other} and '{}' with {}: shards of \
                 different builds do not merge (rerun one shard with the other's build)",
                p.dir,
                first.dir,
                want.1
            );
        }
        if build(p.meta) != want {
            bail!(
                "'{}' ({} built by {}) and '{}' ({} built by {}) come from different builds: \
                 they do not merge",
                p.dir,
                p.meta.version,
                p.meta.rustc,
                first.dir,
                want.0,
                want.2
            );
        }
    }
    Ok(())
}

/// Every session of every shard ran on the first shard's kind of machine.
fn same_machine(parts: &[ShardMeta<'_>]) -> anyhow::Result<()> {
    let first = &parts[0];
    let want = &first.meta.machine;
    for p in parts {
        let machines =
            std::iter::once(&p.meta.machine).chain(p.meta.sessions.iter().map(|s| &s.machine));
        if let Some(other) = machines.into_iter().find(|m| !m.same_hardware(want)) {
            bail!(
                "'{}' ran on {} but '{}' on {}: shards from different machines are a \
                 comparison, not a merge (`bench-sph report A B` compares machines)",
                p.dir,
                other.label(),
                first.dir,
                want.label()
            );
        }
    }
    Ok(())
}
