//! One sweep at a time per results directory: an exclusive OS lock on `DIR/sweep.lock`.
//!
//! The lock is the operating system's (`flock`-style, through std's [`File::try_lock`]), so it
//! is released when the process ends in any way, a crash or `kill -9` included; a lock file
//! left behind by a dead sweep is simply locked again. The file holds the holder's PID, so a
//! refused sweep can name it. The file is never deleted: deleting it would let a sweep that
//! opened the old file and one that created a new file both hold "the" lock.

use std::fs::{File, OpenOptions, TryLockError};
use std::io::{Read, Seek, Write};
use std::path::{Path, PathBuf};

use anyhow::{Context, bail};

pub use crate::results::LOCK_FILE;

/// Held for as long as the sweep runs; dropping it releases the lock.
#[derive(Debug)]
pub struct DirLock {
    _file: File,
    path: PathBuf,
}

impl DirLock {
    /// The lock file.
    pub fn path(&self) -> &Path {
        &self.path
    }
}

/// Locks `dir` (which must exist) for this process, or says which process holds it.
pub fn acquire(dir: &Path) -> anyhow::Result<DirLock> {
    let path = dir.join(LOCK_FILE);
    let mut file = OpenOptions::new()
        .read(true)
        .write(true)
        .create(true)
        .truncate(false)
        .open(&path)
        .with_context(|| format!("cannot lock results directory '{}'", dir.display()))?;
    match file.try_lock() {
        Ok(()) => {}
        Err(TryLockError::WouldBlock) => {
            let mut holder = String::new();
            let _ = file.read_to_string(&mut holder);
            let holder = match holder.trim().parse::<u32>() {
                Ok(pid) => format!("PID {pid}"),
                Err(_) => "a process that is just starting".to_owned(),
            };
            bail!(
                "results directory '{}' is in use by another bench-sph sweep ({holder}); wait \
                 for it to finish (two sweeps at once would also spoil each other's timings)",
                dir.display()
            );
        }
        Err(TryLockError::Error(e)) => {
            return Err(e)
                .with_context(|| format!("cannot lock results directory '{}'", dir.display()));
        }
    }
    file.set_len(0)
        .and_then(|()| file.rewind())
        .and_then(|()| writeln!(file, "{}", std::process::id()))
        .and_then(|()| file.flush())
        .with_context(|| format!("cannot write '{}'", path.display()))?;
    Ok(DirLock { _file: file, path })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_second_lock_on_the_same_directory_is_refused_naming_the_holder() {
        let dir = tempfile::tempdir().unwrap();
        let first = acquire(dir.path()).unwrap();
        let err = acquire(dir.path()).unwrap_err().to_string();
        assert!(
            err.contains(&format!("PID {}", std::process::id())),
            "{err}"
        );
        drop(first);
        let again = acquire(dir.path()).unwrap();
        assert!(again.path().ends_with(LOCK_FILE));
    }
}
