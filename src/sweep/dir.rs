//! The results directory of a sweep: choosing it, locking it, and what may already be in it.
//!
//! A new sweep's directory must be new or empty, or hold only a sweep's own earlier output
//! (`trials.csv`, `summary.csv`, its `meta.json`, `sweep.lock`, a merge's `references.csv`, and the report the sweep drew:
//! `REPORT.md` and chart PNGs); that earlier output is replaced only with `--force`, and then
//! all of it, so no REPORT.md or chart of the old data stays beside the new. Trace directories
//! inside are left alone. Anything else is refused (see [`crate::output::claim`]).
//!
//! Before looking inside, the sweep takes the directory's lock ([`super::lock`]), so of two
//! sweeps started on the same directory at the same moment, the loser is always refused with
//! a message about that directory.

use std::path::{Path, PathBuf};

use anyhow::{Context, bail};

use super::lock::{self, DirLock, LOCK_FILE};
use super::{META_FILE, SUMMARY_FILE, TRIALS_FILE};
use crate::output::claim::{self, Owner};
use crate::results::REFERENCES_FILE;
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

/// Locks `dir` for a new sweep and makes it ready: refuses foreign files (unless `force`)
/// and a sweep's earlier output (unless `force`, which removes it). Returns the held lock.
pub fn open_new(dir: &Path, force: bool) -> anyhow::Result<DirLock> {
    if dir.exists() && !dir.is_dir() {
        bail!("--out '{}' exists and is not a directory", dir.display());
    }
    std::fs::create_dir_all(dir)
        .with_context(|| format!("cannot create results directory '{}'", dir.display()))?;
    if !dir.join(LOCK_FILE).exists() {
        // Not a sweep's directory yet: refuse before creating a lock file in it, so that a
        // refused sweep leaves nothing behind. (The lock file is never deleted: see `lock`.)
        check_contents(dir, force, false)?;
    }
    let held = lock::acquire(dir)?;
    // Again under the lock, which makes it authoritative.
    check_contents(dir, force, true)?;
    Ok(held)
}

/// Refuses foreign files (unless `force`) and a sweep's earlier output (unless `force`; with
/// `remove`, then removes it).
fn check_contents(dir: &Path, force: bool, remove: bool) -> anyhow::Result<()> {
    let owner = Owner {
        command: "bench-sph sweep",
        option: "--out",
        owns: &owned,
        tolerates: &is_trace_dir,
    };
    let claimed = claim::claim(dir, &owner, force)?;
    for name in [
        TRIALS_FILE,
        SUMMARY_FILE,
        META_FILE,
        REFERENCES_FILE,
        crate::results::REPORT_FILE,
    ] {
        claimed.check_writable(name)?;
    }
    let earlier: Vec<&PathBuf> = claimed
        .earlier()
        .iter()
        .filter(|p| !p.ends_with(LOCK_FILE))
        .collect();
    if !earlier.is_empty() {
        if !force {
            bail!(
                "results directory '{}' already holds a sweep's results; continue that sweep \
                 with `--resume {}`, or replace them (and their report) with `--force`",
                dir.display(),
                dir.display()
            );
        }
        for path in earlier.into_iter().filter(|_| remove) {
            std::fs::remove_file(path)
                .with_context(|| format!("cannot replace '{}'", path.display()))?;
        }
    }
    Ok(())
}

/// Locks an existing sweep's directory for `--resume`. Where a lock file exists, the lock is
/// taken first, so a sweep that has just started there (locked, `meta.json` not yet written)
/// is reported as the holder; a lock file is never created in a directory that is not a
/// sweep's.
pub fn open_existing(dir: &Path) -> anyhow::Result<DirLock> {
    let meta = dir.join(META_FILE);
    if !dir.is_dir() {
        bail!("cannot resume '{}': no such directory", dir.display());
    }
    let held = if dir.join(LOCK_FILE).is_file() {
        Some(lock::acquire(dir)?)
    } else {
        None
    };
    if !Meta::is_sweep_meta(&meta) {
        bail!(
            "cannot resume '{}': it has no sweep's {META_FILE}, so it is not a sweep's results \
             directory",
            dir.display()
        );
    }
    match held {
        Some(lock) => Ok(lock),
        None => lock::acquire(dir),
    }
}

/// Whether a top-level entry of a results directory is a sweep's own output.
fn owned(path: &Path) -> bool {
    let Some(name) = path.file_name().and_then(|n| n.to_str()) else {
        return false;
    };
    if !path.is_file() {
        return false;
    }
    match name {
        // By contents too: a hand-written trials.csv is not ours to replace (an empty one,
        // left by a sweep killed as it started, holds nothing to lose).
        TRIALS_FILE | SUMMARY_FILE | REFERENCES_FILE => {
            std::fs::metadata(path).is_ok_and(|m| m.len() == 0)
                || crate::output::sniff::starts_with(path, b"strategy,neighbors,preset,n,steps,")
        }
        LOCK_FILE => true,
        META_FILE => Meta::is_sweep_meta(path),
        _ => crate::results::is_report_file(path),
    }
}

/// Trace directories may sit inside a results directory (the report embeds them).
fn is_trace_dir(path: &Path) -> bool {
    path.is_dir() && path.join("timeline.png").is_file() && path.join("stats.csv").is_file()
}
