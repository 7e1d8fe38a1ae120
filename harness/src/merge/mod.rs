//! `bench-sph merge`: one results directory from the shards of a sweep (`sweep --shard I/K`),
//! which a batch scheduler ran on identical nodes.
//!
//! The pipeline: the shards are checked to be distinct directories; each is read under a
//! shared, read-only lock (a sweep writing it refuses the merge; the merge never writes into a
//! shard, so shards on a read-only mount merge), keeping its believed cells: those
//! `bench-sph report` believes ([`crate::results::validate::cell`]) whose trials and rounds
//! are also those of the shard's plan ([`check::against_plan`]); every row left out is named
//! with why, on standard error and in the merge's `meta.json` (so in its report). [`check`]
//! refuses directories that a sweep did not write, shards of different plans, splits, builds
//! or machines, repeated shards and an edited `planned_cells`; [`assemble`] puts the whole
//! plan together, one row per cell, each keeping its own shard's speedup (`reference_shard`).
//! A cell no shard has, or a shard's `seq` reference left out (its cells would have no
//! denominator), is an error unless `--allow-partial`, which marks the merge `partial`.
//! The output directory is claimed like a new sweep's (locked, and recorded as the merge's:
//! [`crate::output::record`]) and written file by file through temporary names: `summary.csv`,
//! `trials.csv`, `references.csv` (every shard's `seq` rows)
//! and `meta.json` (the plan's parameters without the shard, every shard's sessions, and
//! `merge`: where each cell came from, what is missing, what was warned about).

pub mod assemble;
pub mod check;

use std::path::{Path, PathBuf};

use anyhow::{Context, bail};

use crate::output::console::plural;
use crate::output::lock;
use crate::output::record::Command;
use crate::results::export::to_csv;
use crate::results::load::{Dropped, believed_with, read_summary, read_trials};
use crate::results::meta::{Merge, MergedShard, Meta, SweepStatus};
use crate::results::rows::{SUMMARY_COLUMNS, SummaryRow, TRIAL_COLUMNS, TrialRow};
use crate::results::{META_FILE, REFERENCES_FILE, SUMMARY_FILE, TRIALS_FILE};
use crate::sweep::Plan;
use assemble::Part;

/// One invocation of `bench-sph merge`.
#[derive(Debug, Clone)]
pub struct Request {
    /// The shard directories.
    pub dirs: Vec<PathBuf>,
    /// The merged results directory.
    pub out: PathBuf,
    /// Merge even when cells are missing (the result is marked partial).
    pub allow_partial: bool,
    /// Replace an earlier sweep's or merge's results in `out`.
    pub force: bool,
}

/// What a merge wrote.
#[derive(Debug)]
pub struct Merged {
    /// The merged directory.
    pub dir: PathBuf,
    /// The plan's fingerprint.
    pub fingerprint: String,
    /// Cells in the merge, and in the whole plan.
    pub cells: (usize, usize),
    /// Trial rows in the merge.
    pub trial_rows: usize,
    /// `seq` rows in `references.csv`.
    pub references: usize,
    /// Lines to show as warnings: every row left out of a shard and why, then what else the
    /// merge found (also in `meta.json`'s `merge.warnings`).
    pub warnings: Vec<String>,
}

/// A shard directory, read.
struct Read {
    dir: PathBuf,
    meta: Meta,
    rows: Vec<SummaryRow>,
    trials: Vec<TrialRow>,
    /// Its cells left out, each with why.
    dropped: Vec<Dropped>,
    /// One line per row or line left out (unreadable lines, cells not believed, trial rows
    /// of no summary row), naming the directory.
    left_out: Vec<String>,
}

/// Merges `request.dirs` into `request.out` (see the module docs).
pub fn run(request: &Request) -> anyhow::Result<Merged> {
    refuse_repeated_inputs(&request.dirs)?;
    refuse_output_among_inputs(request)?;
    let read = request
        .dirs
        .iter()
        .map(|d| read_shard(d))
        .collect::<anyhow::Result<Vec<_>>>()?;
    let metas: Vec<check::ShardMeta<'_>> = read
        .iter()
        .map(|r| check::ShardMeta {
            dir: r.dir.display().to_string(),
            meta: &r.meta,
        })
        .collect();
    let shards = check::shards(&metas)?;
    let params = crate::results::params::SweepParams {
        shard: None,
        ..read[0].meta.params.clone()
    };
    let whole = Plan::new(&params);
    let parts: Vec<Part> = read
        .iter()
        .zip(&shards)
        .map(|(r, &shard)| Part {
            shard,
            dir: r.dir.display().to_string(),
            rows: r.rows.clone(),
            trials: r.trials.clone(),
            dropped: r.dropped.clone(),
        })
        .collect();
    let merged = assemble::assemble(&whole, &parts)?;
    let left_out: Vec<String> = read.iter().flat_map(|r| r.left_out.clone()).collect();
    if !request.allow_partial {
        if !merged.unreferenced.is_empty() {
            bail!(unreferenced_text(&merged.unreferenced, &left_out));
        }
        if !merged.missing.is_empty() {
            bail!(missing_text(
                &whole,
                &read,
                &shards,
                &merged.missing,
                &left_out
            ));
        }
    }
    let mut warnings: Vec<String> = left_out
        .iter()
        .map(|l| format!("left out of the merge: {l}"))
        .collect();
    warnings.extend(merged.disagreements.iter().cloned());
    for u in &merged.unreferenced {
        warnings.push(format!(
            "{} (--allow-partial: they keep their times; references.csv holds that seq as a \
             failed row saying why)",
            u.describe()
        ));
    }
    if !merged.missing.is_empty() {
        warnings.push(format!(
            "the merge is partial: {} (--allow-partial); its report says so",
            missing_count(merged.missing.len(), whole.cells.len())
        ));
    }
    if read.iter().any(|r| r.meta.git_dirty) {
        warnings.push(format!(
            "the shards were measured by a build with uncommitted changes ({}): bench-sph \
             cannot prove they ran the same code",
            read[0].meta.git_commit
        ));
    }
    let meta = merged_meta(&read, &shards, &params, &whole, &merged, &warnings);
    let mut claimed = crate::results::dir::open_new(
        &request.out,
        request.force,
        Command::Merge,
        &[REFERENCES_FILE],
    )?;
    claimed.record(&[TRIALS_FILE, SUMMARY_FILE, REFERENCES_FILE, META_FILE])?;
    write_all(&request.out, &merged, &meta)?;
    drop(claimed);
    Ok(Merged {
        dir: request.out.clone(),
        fingerprint: params.fingerprint(),
        cells: (merged.summary.len(), whole.cells.len()),
        trial_rows: merged.trials.len(),
        references: merged.references.len(),
        warnings,
    })
}

/// The same directory twice (under any path) would count its cells twice: refused before
/// anything is read.
fn refuse_repeated_inputs(dirs: &[PathBuf]) -> anyhow::Result<()> {
    let mut seen: Vec<(PathBuf, &Path)> = Vec::new();
    for d in dirs {
        let canonical = d
            .canonicalize()
            .with_context(|| format!("cannot read the shard directory '{}'", d.display()))?;
        if let Some((_, first)) = seen.iter().find(|(c, _)| *c == canonical) {
            bail!(
                "'{}' is given twice (also as '{}'): each shard directory once",
                d.display(),
                first.display()
            );
        }
        seen.push((canonical, d));
    }
    Ok(())
}

/// `--out` must not be one of the shards: `--force` would replace a shard's results.
fn refuse_output_among_inputs(request: &Request) -> anyhow::Result<()> {
    let Ok(out) = request.out.canonicalize() else {
        return Ok(()); // Not there yet: not an input.
    };
    for d in &request.dirs {
        if d.canonicalize().is_ok_and(|d| d == out) {
            bail!(
                "--out '{}' is one of the shards being merged: write the merge to a new \
                 directory",
                request.out.display()
            );
        }
    }
    Ok(())
}

/// Reads a shard directory under a shared lock (read-only: see [`lock::for_reading`]):
/// `meta.json`, and the cells of `summary.csv` whose trials in `trials.csv` bear them out
/// (others are left out: they count as missing).
fn read_shard(dir: &Path) -> anyhow::Result<Read> {
    let _reading = lock::for_reading(dir).context("cannot merge now")?;
    if std::fs::symlink_metadata(dir.join(META_FILE)).is_err() {
        bail!(
            "'{}' is not a results directory of bench-sph sweep (no {META_FILE})",
            dir.display()
        );
    }
    let meta = Meta::read(&dir.join(META_FILE))?;
    let (summary, bad_summary) = read_summary(&dir.join(SUMMARY_FILE))
        .with_context(|| format!("cannot merge '{}'", dir.display()))?;
    let (trials, bad_trials) = read_trials(&dir.join(TRIALS_FILE))
        .with_context(|| format!("cannot merge '{}'", dir.display()))?;
    let params = &meta.params;
    let believed = believed_with(summary, Some(trials), &|row, trials| {
        check::against_plan(row, trials, params)
    });
    let named = |d: &Dropped| format!("'{}': {d}", dir.display());
    let left_out = bad_summary
        .into_iter()
        .chain(bad_trials)
        .chain(believed.dropped.iter().map(named))
        .chain(believed.without_summary.iter().map(named))
        .collect();
    Ok(Read {
        dir: dir.to_path_buf(),
        meta,
        rows: believed.rows,
        trials: believed.trials,
        dropped: believed.dropped,
        left_out,
    })
}

/// The rows left out of the shards, one per line (under an error's first line), or nothing.
fn left_out_text(left_out: &[String]) -> String {
    if left_out.is_empty() {
        return String::new();
    }
    let lines: String = left_out.iter().map(|l| format!("\n  - {l}")).collect();
    format!(
        "\n{} left out of the shards, as `bench-sph report` would leave {} out:{lines}",
        plural(left_out.len(), "row or line was", "rows or lines were"),
        if left_out.len() == 1 { "it" } else { "them" }
    )
}

/// Why a merge without `--allow-partial` is refused when a shard's `seq` reference was left
/// out.
fn unreferenced_text(unreferenced: &[assemble::Unreferenced], left_out: &[String]) -> String {
    let each: Vec<String> = unreferenced.iter().map(|u| u.describe()).collect();
    format!(
        "{}. Resume or run that shard again (`bench-sph sweep --resume {}` measures what it \
         drops), then merge again; or merge with --allow-partial to keep those cells without a \
         speedup (the study is then marked partial){}",
        each.join("; "),
        unreferenced[0].dir,
        left_out_text(left_out)
    )
}

/// Why a merge without `--allow-partial` is refused: how many cells are missing, and which
/// shards are absent or unfinished.
fn missing_text(
    whole: &Plan,
    read: &[Read],
    shards: &[crate::results::shard::Shard],
    missing: &[crate::results::key::Cell],
    left_out: &[String],
) -> String {
    let count = shards[0].count;
    let mut causes = Vec::new();
    let absent: Vec<String> = (1..=count)
        .filter(|i| !shards.iter().any(|s| s.index == *i))
        .map(|i| format!("{i}/{count}"))
        .collect();
    if !absent.is_empty() {
        causes.push(format!("not given: shard {}", absent.join(", ")));
    }
    for (r, s) in read.iter().zip(shards) {
        if r.meta.status != SweepStatus::Complete {
            causes.push(format!(
                "shard {s} is {} (`bench-sph sweep --resume {}`)",
                r.meta.status.as_str(),
                r.dir.display()
            ));
        }
    }
    if !left_out.is_empty() {
        causes.push(
            "rows of the shards left out (listed below; `bench-sph sweep --resume SHARD_DIR` \
             measures them again)"
                .to_owned(),
        );
    }
    format!(
        "{} (the first: {}){}; merge with --allow-partial to merge what there is (the study is \
         then marked partial){}",
        missing_count(missing.len(), whole.cells.len()),
        missing[0].label_with_group(),
        match causes.is_empty() {
            true => String::new(),
            false => format!(": {}", causes.join("; ")),
        },
        left_out_text(left_out)
    )
}

/// `1 of the plan's 7 cells is missing`.
fn missing_count(missing: usize, planned: usize) -> String {
    format!(
        "{missing} of the plan's {planned} cells {} missing",
        if missing == 1 { "is" } else { "are" }
    )
}

/// The merged `meta.json`: the first shard's, with the plan's parameters, every shard's
/// sessions and the merge's own record.
fn merged_meta(
    read: &[Read],
    shards: &[crate::results::shard::Shard],
    params: &crate::results::params::SweepParams,
    whole: &Plan,
    merged: &assemble::Assembled,
    warnings: &[String],
) -> Meta {
    let mut order: Vec<usize> = (0..read.len()).collect();
    order.sort_by_key(|&i| shards[i].index);
    let first = &read[order[0]].meta;
    let complete = merged.missing.is_empty() && merged.unreferenced.is_empty();
    Meta {
        params: params.clone(),
        planned_cells: whole.cells.len(),
        status: if complete {
            SweepStatus::Complete
        } else {
            SweepStatus::Partial
        },
        started_utc: order
            .iter()
            .map(|&i| read[i].meta.started_utc.clone())
            .min()
            .unwrap_or_default(),
        finished_utc: Some(crate::results::meta::now_utc()),
        sessions: order
            .iter()
            .flat_map(|&i| read[i].meta.sessions.clone())
            .collect(),
        plan_fingerprint: Some(params.fingerprint()),
        merge: Some(Merge {
            shards: order
                .iter()
                .map(|&i| MergedShard {
                    shard: shards[i],
                    dir: read[i].dir.display().to_string(),
                    status: read[i].meta.status,
                    cells: merged
                        .cells_from
                        .get(&shards[i].index)
                        .copied()
                        .unwrap_or(0),
                })
                .collect(),
            missing_cells: merged
                .missing
                .iter()
                .map(|c| c.label_with_group())
                .collect(),
            without_reference: merged
                .unreferenced
                .iter()
                .flat_map(|u| u.cells.iter().map(|c| c.label_with_group()))
                .collect(),
            warnings: warnings.to_vec(),
        }),
        ..first.clone()
    }
}

/// Writes the merged files, each through a temporary name; `meta.json` last, so a directory
/// with a merge's `meta.json` has all of its files.
fn write_all(dir: &Path, merged: &assemble::Assembled, meta: &Meta) -> anyhow::Result<()> {
    let csv = |r: csv::Result<Vec<u8>>| r.context("cannot write the merged CSV files");
    crate::output::atomic::write(
        &dir.join(TRIALS_FILE),
        &csv(to_csv(&TRIAL_COLUMNS, &merged.trials))?,
    )?;
    crate::output::atomic::write(
        &dir.join(SUMMARY_FILE),
        &csv(to_csv(&SUMMARY_COLUMNS, &merged.summary))?,
    )?;
    crate::output::atomic::write(
        &dir.join(REFERENCES_FILE),
        &csv(to_csv(&SUMMARY_COLUMNS, &merged.references))?,
    )?;
    meta.write(&dir.join(META_FILE))
}
