//! The refusals of `bench-sph merge`, as pure functions of the shards' `meta.json`: only the
//! shards of one plan, measured by one build on one kind of machine, merge.

use std::collections::HashMap;

use anyhow::bail;

use crate::results::meta::Meta;
use crate::results::shard::Shard;

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
    let mut seen: HashMap<usize, &str> = HashMap::new();
    for p in parts {
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
        if let Some(other) = seen.insert(shard.index, &p.dir) {
            bail!(
                "shard {shard} is given twice ('{other}' and '{}'): each cell must count once",
                p.dir
            );
        }
        shards.push(shard);
    }
    let first_shard = shards[0];
    for (p, s) in parts.iter().zip(&shards) {
        if s.count != first_shard.count {
            bail!(
                "'{}' is shard {s} but '{}' is shard {first_shard}: shards of different splits \
                 of a plan do not merge",
                p.dir,
                first.dir
            );
        }
    }
    same_plan(parts)?;
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
