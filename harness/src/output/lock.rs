//! One writer per directory: every command that writes an output directory (`sweep`, `merge`,
//! `report`, `trace`, `render --frames`, `validate`) holds an exclusive OS lock on
//! `DIR/bench-sph.lock` for as long as it writes there, and a second writer, of any command,
//! is refused naming the holder: `'D' is in use by bench-sph trace (PID 123)`.
//!
//! - The lock is the operating system's (`flock`-style, through std's [`File::try_lock`]), so
//!   it is released when the process ends in any way, a crash or `kill -9` included; a lock
//!   file left behind is simply locked again. The file holds the holder's command and PID
//!   (`trace 123`) so that a refused command can name it. It is never deleted: deleting it
//!   would let a command that opened the old file and one that created a new file both hold
//!   "the" lock.
//! - Within one process a directory's lock is taken once and shared ([`acquire`] again returns
//!   the same lock): a sweep draws its report into its own directory under its own lock.
//! - **Reading** a directory needs no write access: [`for_reading`] opens an existing lock
//!   file read-only and takes a shared lock, which only a writer's exclusive lock refuses;
//!   where there is no lock file, or it cannot be opened or locked (a read-only mount without
//!   locks), the reader goes on. A reader never writes into the directory.
//!
//! Older versions locked only sweeps, on `sweep.lock` ([`LEGACY_LOCK_FILE`]); that file is
//! left alone, and [`for_reading`] respects a lock still held on it.

use std::fs::{File, OpenOptions, TryLockError};
use std::io::{Read, Seek, Write};
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex, PoisonError, Weak};

use anyhow::{Context, bail};

use super::record::Command;
use crate::io::capped;

/// The lock file of every directory bench-sph writes.
pub const LOCK_FILE: &str = "bench-sph.lock";
/// The lock file of sweeps written by earlier versions.
pub const LEGACY_LOCK_FILE: &str = "sweep.lock";

/// The locks this process holds, by canonical directory.
static HELD: Mutex<Vec<(PathBuf, Weak<Held>)>> = Mutex::new(Vec::new());

fn held() -> std::sync::MutexGuard<'static, Vec<(PathBuf, Weak<Held>)>> {
    HELD.lock().unwrap_or_else(PoisonError::into_inner)
}

#[derive(Debug)]
struct Held {
    _file: File,
    key: PathBuf,
}

impl Drop for Held {
    fn drop(&mut self) {
        held().retain(|(k, w)| k != &self.key && w.strong_count() > 0);
    }
}

/// A directory's exclusive lock, held until the last clone is dropped.
#[derive(Debug, Clone)]
pub struct DirLock {
    _held: Arc<Held>,
}

/// Locks `dir` (which must exist) for `command` of this process, or says which process holds
/// it. A lock this process already holds on `dir` is shared, not taken again.
pub fn acquire(dir: &Path, command: Command) -> anyhow::Result<DirLock> {
    let context = || format!("cannot lock directory '{}'", dir.display());
    let key = dir.canonicalize().with_context(context)?;
    let mut registry = held();
    if let Some(held) = registry
        .iter()
        .find(|(k, _)| *k == key)
        .and_then(|(_, w)| w.upgrade())
    {
        return Ok(DirLock { _held: held });
    }
    let path = dir.join(LOCK_FILE);
    refuse_odd_lock_file(&path)?;
    let mut file = options(true).open(&path).with_context(context)?;
    if !file.metadata().with_context(context)?.is_file() {
        bail!("'{}' is not a regular file: remove it", path.display());
    }
    match file.try_lock() {
        Ok(()) => {}
        Err(TryLockError::WouldBlock) => {
            bail!(
                "'{}' is in use by {}",
                dir.display(),
                holder_text(&holder(&mut file))
            )
        }
        Err(TryLockError::Error(e)) => return Err(e).with_context(context),
    }
    file.set_len(0)
        .and_then(|()| file.rewind())
        .and_then(|()| writeln!(file, "{} {}", command.name(), std::process::id()))
        .and_then(|()| file.flush())
        .with_context(|| format!("cannot write '{}'", path.display()))?;
    let held = Arc::new(Held {
        _file: file,
        key: key.clone(),
    });
    registry.retain(|(_, w)| w.strong_count() > 0);
    registry.push((key, Arc::downgrade(&held)));
    Ok(DirLock { _held: held })
}

/// A shared hold on a directory being read; see the module docs.
#[derive(Debug)]
pub struct ReadLock {
    _files: Vec<File>,
}

/// Takes a shared lock on `dir` to read it, refusing while a command writes it; never writes
/// into `dir` (see the module docs).
pub fn for_reading(dir: &Path) -> anyhow::Result<ReadLock> {
    let mut files = Vec::new();
    for name in [LOCK_FILE, LEGACY_LOCK_FILE] {
        let path = dir.join(name);
        if !std::fs::symlink_metadata(&path).is_ok_and(|m| m.is_file()) {
            continue;
        }
        let Ok(mut file) = options(false).open(&path) else {
            continue; // Not ours to read: the reader goes on without it.
        };
        match file.try_lock_shared() {
            Ok(()) => files.push(file),
            Err(TryLockError::WouldBlock) => bail!(
                "'{}' is being written by {}",
                dir.display(),
                holder_text(&holder(&mut file))
            ),
            Err(TryLockError::Error(_)) => {} // No locks on this filesystem: go on.
        }
    }
    Ok(ReadLock { _files: files })
}

/// Refuses a lock file that is not a plain file (a link to `/dev/zero`, a FIFO, a directory)
/// before opening it.
fn refuse_odd_lock_file(path: &Path) -> anyhow::Result<()> {
    match std::fs::symlink_metadata(path) {
        Ok(m) if !m.is_file() => bail!(
            "'{}' is not a regular file (bench-sph's lock file must be): remove it",
            path.display()
        ),
        _ => Ok(()),
    }
}

/// How a lock file is opened: never through a link, never waiting on a FIFO.
fn options(write: bool) -> OpenOptions {
    let mut options = OpenOptions::new();
    options
        .read(true)
        .write(write)
        .create(write)
        .truncate(false);
    #[cfg(unix)]
    {
        use std::os::unix::fs::OpenOptionsExt;
        options.custom_flags(nix::libc::O_NOFOLLOW | nix::libc::O_NONBLOCK);
    }
    options
}

/// Who holds a lock, as its file says.
#[derive(Debug, Clone, PartialEq, Eq)]
struct Holder {
    /// The command (`None` in an older version's `sweep.lock`, which held only the PID).
    command: Option<Command>,
    /// Its process, if the file names one.
    pid: Option<u32>,
}

fn holder(file: &mut File) -> Holder {
    let mut text = String::new();
    let _ = file
        .rewind()
        .and_then(|()| file.take(capped::LOCK.cap).read_to_string(&mut text));
    parse_holder(&text)
}

fn parse_holder(text: &str) -> Holder {
    let mut words = text.split_whitespace();
    let (first, second) = (words.next(), words.next());
    match (first, second) {
        (Some(command), Some(pid)) => Holder {
            command: Command::from_name(command),
            pid: pid.parse().ok(),
        },
        (Some(pid), None) => Holder {
            command: None,
            pid: pid.parse().ok(),
        },
        _ => Holder {
            command: None,
            pid: None,
        },
    }
}

/// `bench-sph trace (PID 123); wait for it to finish`, or what is known.
fn holder_text(holder: &Holder) -> String {
    let command = holder
        .command
        .map_or_else(|| "bench-sph".to_owned(), |c| c.to_string());
    match holder.pid.filter(|&pid| alive(pid)) {
        Some(pid) => {
            let timings = match holder.command {
                Some(Command::Sweep) => {
                    " (a second command there now would also spoil the sweep's timings)"
                }
                _ => "",
            };
            format!("{command} (PID {pid}); wait for it to finish{timings}")
        }
        // The file names no live process: a command that is just starting, or a merge that
        // holds a shared lock while it reads (it cannot write its PID there).
        None => "another bench-sph process (one just starting, or a merge reading it); try \
                 again once it has finished"
            .to_owned(),
    }
}

/// Whether process `pid` exists (always true where that cannot be told).
fn alive(pid: u32) -> bool {
    if cfg!(target_os = "linux") {
        Path::new("/proc").join(pid.to_string()).exists()
    } else {
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_lock_is_shared_within_a_process_and_released_with_its_last_holder() {
        let dir = tempfile::tempdir().unwrap();
        let first = acquire(dir.path(), Command::Sweep).unwrap();
        let again = acquire(dir.path(), Command::Report).unwrap();
        let text = std::fs::read_to_string(dir.path().join(LOCK_FILE)).unwrap();
        assert_eq!(text, format!("sweep {}\n", std::process::id()));
        drop(first);
        drop(again);
        // Only this directory's entry: other tests hold locks on theirs meanwhile.
        let key = dir.path().canonicalize().unwrap();
        assert!(
            held()
                .iter()
                .all(|(k, w)| *k != key || w.strong_count() == 0)
        );
        let _third = acquire(dir.path(), Command::Trace).unwrap();
        let text = std::fs::read_to_string(dir.path().join(LOCK_FILE)).unwrap();
        assert!(text.starts_with("trace "), "{text}");
    }

    #[test]
    fn a_reader_is_refused_while_a_writer_holds_the_lock_naming_it() {
        let dir = tempfile::tempdir().unwrap();
        let _lock = acquire(dir.path(), Command::Trace).unwrap();
        let err = for_reading(dir.path()).unwrap_err().to_string();
        assert!(
            err.contains(&format!(
                "is being written by bench-sph trace (PID {})",
                std::process::id()
            )),
            "{err}"
        );
    }

    #[test]
    fn a_reader_takes_a_shared_lock_and_writes_nothing() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join(LOCK_FILE), "sweep 1\n").unwrap();
        let _a = for_reading(dir.path()).unwrap();
        let _b = for_reading(dir.path()).unwrap();
        assert_eq!(
            std::fs::read_to_string(dir.path().join(LOCK_FILE)).unwrap(),
            "sweep 1\n"
        );
        let bare = tempfile::tempdir().unwrap();
        let _c = for_reading(bare.path()).unwrap();
        assert_eq!(std::fs::read_dir(bare.path()).unwrap().count(), 0);
    }

    #[test]
    fn the_holder_is_read_in_this_and_the_older_format() {
        assert_eq!(
            parse_holder("trace 42\n"),
            Holder {
                command: Some(Command::Trace),
                pid: Some(42)
            }
        );
        assert_eq!(
            parse_holder("42\n"),
            Holder {
                command: None,
                pid: Some(42)
            }
        );
        assert_eq!(parse_holder("").pid, None);
        let me = std::process::id();
        let text = holder_text(&Holder {
            command: Some(Command::Merge),
            pid: Some(me),
        });
        assert_eq!(
            text,
            format!("bench-sph merge (PID {me}); wait for it to finish")
        );
    }

    #[cfg(unix)]
    #[test]
    fn a_lock_file_that_is_a_link_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        std::os::unix::fs::symlink("/dev/zero", dir.path().join(LOCK_FILE)).unwrap();
        let err = acquire(dir.path(), Command::Sweep).unwrap_err().to_string();
        assert!(err.contains("is not a regular file"), "{err}");
    }
}
