//! The results directory of a sweep (or of a merge of shards): choosing it, locking it, and
//! what may already be in it.
//!
//! A new sweep's (or merge's) directory must be new or empty, or hold only the results of an
//! earlier sweep or merge and the report drawn there — as the directory's record says
//! ([`crate::output::record`]), never as names suggest. That earlier output is replaced only
//! with `--force`, and then all of it, so no REPORT.md or chart of the old data stays beside
//! the new. Trace directories inside are left alone. Anything else is refused unless
//! `--force`, which writes beside it and never replaces it (see [`crate::output::claim`]).
//!
//! Before it changes anything, the command holds the directory's lock
//! ([`crate::output::lock`]), so of two commands started on one directory at the same moment,
//! the loser is always refused with a message about that directory and its holder.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use anyhow::{Context, bail};

use super::files::{META_FILE, SUMMARY_FILE, TRIALS_FILE};
use crate::output::claim::{self, Claimed, Owner};
use crate::output::lock::{self, DirLock, LOCK_FILE};
use crate::output::record::{self, Command, Record};
use crate::results::REPORT_FILE;
use crate::results::meta::Meta;

/// The default results directory: `results/<UTC timestamp>`, or with `-2`, `-3`, … when a
/// sweep started in the same second took that name. Created here, exclusively.
pub fn new_default() -> anyhow::Result<PathBuf> {
    let parent = Path::new("results");
    std::fs::create_dir_all(parent)
        .with_context(|| format!("cannot create directory '{}'", parent.display()))?;
    let stamp = crate::results::meta::timestamp_dir_name();
    for k in 1..1000 {
        let name = if k == 1 {
            stamp.clone()
        } else {
            format!("{stamp}-{k}")
        };
        let dir = parent.join(name);
        match std::fs::create_dir(&dir) {
            Ok(()) => return Ok(dir),
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => continue,
            Err(e) => {
                return Err(e)
                    .with_context(|| format!("cannot create directory '{}'", dir.display()));
            }
        }
    }
    bail!(
        "cannot choose a results directory: results/{stamp} to results/{stamp}-999 all exist; \
         pass --out DIR"
    )
}

/// Locks and claims `dir` for a new sweep or merge (`command`) that writes `also` beside the
/// results files and the report: refuses foreign files (unless `force`, which leaves them
/// untouched) and earlier results (unless `force`, which removes them and the report drawn
/// there). Returns the claimed directory, still locked.
pub fn open_new(
    dir: &Path,
    force: bool,
    command: Command,
    also: &[&'static str],
) -> anyhow::Result<Claimed> {
    if dir.exists() && !dir.is_dir() {
        bail!("--out '{}' exists and is not a directory", dir.display());
    }
    std::fs::create_dir_all(dir)
        .with_context(|| format!("cannot create results directory '{}'", dir.display()))?;
    // Every file of the results, and the report, must be writable before anything is.
    let mut writes = vec![TRIALS_FILE, SUMMARY_FILE, META_FILE, REPORT_FILE];
    writes.extend(also);
    let owner = Owner {
        command,
        option: "--out",
        replaces: &[Command::Sweep, Command::Merge, Command::Report],
        tolerates: &[],
        tolerates_unrecorded: &is_trace_dir,
        writes: &writes,
    };
    let mut claimed = claim::claim(dir, &owner, force)?;
    if !claimed.earlier().is_empty() {
        if !force {
            bail!(already_holds(dir, command, claimed.earlier()));
        }
        claimed.remove_earlier()?;
    }
    Ok(claimed)
}

/// Why a directory with earlier results is refused, and what to do: what the record says is
/// there (a sweep's results, a merge's output, cut short or not, or only a report).
fn already_holds(dir: &Path, command: Command, earlier: &[(String, Command)]) -> String {
    let d = dir.display();
    let writers: BTreeSet<Command> = earlier.iter().map(|&(_, c)| c).collect();
    let whole = earlier.iter().any(|(n, _)| n == META_FILE);
    let (what, theirs) = if writers.contains(&Command::Merge) {
        let cut = match whole {
            true => "",
            false => " that was cut short (it has no meta.json)",
        };
        (
            format!("the output of a bench-sph merge{cut}"),
            Command::Merge,
        )
    } else if writers.contains(&Command::Sweep) {
        let cut = match whole {
            true => "",
            false => " (cut short before its meta.json)",
        };
        (format!("a sweep's results{cut}"), Command::Sweep)
    } else {
        (
            "a report drawn by bench-sph report".to_owned(),
            Command::Report,
        )
    };
    let advice = match (command, theirs) {
        (Command::Sweep, Command::Sweep) if whole => format!(
            "continue that sweep with `--resume {d}`, or replace them (and their report) with \
             `--force`"
        ),
        (Command::Merge, Command::Merge) => format!(
            "run the merge again with --force to replace it (and its report), or delete '{d}'"
        ),
        _ => format!(
            "pass --force to replace it (and the report drawn there) with this {}'s, or \
             choose another directory",
            command.name()
        ),
    };
    format!("results directory '{d}' already holds {what}; {advice}")
}

/// Locks an existing sweep's directory for `--resume`. What is not a sweep's results is
/// refused before a lock file is created there, and again under the lock. A sweep written
/// before bench-sph kept records is given one: resuming it says its files are the sweep's.
pub fn open_existing(dir: &Path) -> anyhow::Result<DirLock> {
    if !dir.is_dir() {
        bail!("cannot resume '{}': no such directory", dir.display());
    }
    if std::fs::symlink_metadata(dir.join(LOCK_FILE)).is_err() {
        resumable(dir)?;
    }
    let held = lock::acquire(dir, Command::Sweep)?;
    let record = resumable(dir)?.unwrap_or_default();
    let mut unrecorded = Vec::new();
    for name in [TRIALS_FILE, SUMMARY_FILE, META_FILE] {
        match record.writer(name) {
            None => unrecorded.push(name),
            Some(Command::Sweep) => {}
            Some(other) => bail!(
                "cannot resume '{}': its {name} was written by {other}, not by a sweep",
                dir.display()
            ),
        }
    }
    record::add(dir, Command::Sweep, &unrecorded)?;
    Ok(held)
}

/// `dir`'s record, if `dir` holds a sweep's results to resume; the error says what it holds
/// instead (a merge's output, whole or cut short, or nothing of a sweep's).
fn resumable(dir: &Path) -> anyhow::Result<Option<Record>> {
    let d = dir.display();
    let record = Record::read(dir)?;
    let meta = dir.join(META_FILE);
    let merged = record.as_ref().is_some_and(|r| r.has(Command::Merge));
    if !Meta::is_sweep_meta(&meta)? {
        if merged {
            bail!(
                "cannot resume '{d}': it holds the output of a bench-sph merge that was cut \
                 short (it has no meta.json), not a sweep; run the merge again with --force to \
                 replace it, or delete '{d}'"
            );
        }
        bail!(
            "cannot resume '{d}': it has no sweep's {META_FILE}, so it is not a sweep's results \
             directory"
        );
    }
    if merged || Meta::read(&meta)?.merge.is_some() {
        bail!(
            "'{d}' is a merge of shards, not a sweep to resume: resume or run the shards that \
             are missing (`bench-sph sweep --resume SHARD_DIR`) and merge again"
        );
    }
    Ok(record)
}

/// Trace directories may sit inside a results directory (the report embeds them).
fn is_trace_dir(path: &Path) -> bool {
    path.is_dir() && path.join("timeline.png").is_file() && path.join("stats.csv").is_file()
}
