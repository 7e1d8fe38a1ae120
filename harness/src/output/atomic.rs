//! Files written whole or not at all: a temporary file `.NAME.XXXXXX.tmp` beside the
//! destination (`tempfile`'s [`NamedTempFile`], created with the permissions a plain
//! `File::create` would give), synced and renamed over it by [`AtomicFile::commit`]
//! (`persist`). An `AtomicFile` dropped without a commit (an error, a panic, an early return)
//! removes its temporary file, and the destination keeps its earlier contents. A command
//! stopped by a signal runs no destructor: it removes the temporary files it was writing
//! ([`remove_live_temporaries`], from [`crate::signals`]), so an interrupted run leaves none
//! behind either.

use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::{Mutex, PoisonError};

use anyhow::Context;
use tempfile::NamedTempFile;

/// The temporary files being written now, for [`remove_live_temporaries`].
static LIVE: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

fn live() -> std::sync::MutexGuard<'static, Vec<PathBuf>> {
    LIVE.lock().unwrap_or_else(PoisonError::into_inner)
}

/// Removes every temporary file being written now: for a command stopped by a signal
/// ([`crate::signals`]), whose destinations then keep their earlier contents.
pub fn remove_live_temporaries() {
    for tmp in live().iter() {
        let _ = std::fs::remove_file(tmp);
    }
}

/// The suffix of every temporary file (see [`is_temporary`]).
pub const TMP_SUFFIX: &str = ".tmp";

/// Whether a file name is one of [`AtomicFile`]'s temporary names (`.NAME.XXXXXX.tmp`):
/// debris of a killed process, never a result.
pub fn is_temporary(name: &str) -> bool {
    name.starts_with('.') && name.ends_with(TMP_SUFFIX)
}

/// A file being written under a temporary name; see the module docs.
#[derive(Debug)]
pub struct AtomicFile {
    dest: PathBuf,
    tmp: PathBuf,
    out: Option<BufWriter<NamedTempFile>>,
}

impl AtomicFile {
    /// Starts writing `dest` (its directory must exist). Errors name `dest`.
    pub fn create(dest: &Path) -> anyhow::Result<AtomicFile> {
        let context = || format!("cannot write '{}'", dest.display());
        let name = dest
            .file_name()
            .with_context(|| format!("cannot write '{}': not a file name", dest.display()))?;
        let dir = match dest.parent() {
            Some(p) if !p.as_os_str().is_empty() => p,
            _ => Path::new("."),
        };
        let mut builder = tempfile::Builder::new();
        let prefix = format!(".{}.", name.to_string_lossy());
        builder.prefix(&prefix).suffix(TMP_SUFFIX);
        // `NamedTempFile` is private (0600) by default; results are ordinary files (0666
        // less the umask, as `File::create` makes them).
        #[cfg(unix)]
        builder.permissions(std::os::unix::fs::PermissionsExt::from_mode(0o666));
        let file = builder.tempfile_in(dir).with_context(context)?;
        let tmp = file.path().to_path_buf();
        live().push(tmp.clone());
        Ok(AtomicFile {
            dest: dest.to_path_buf(),
            tmp,
            out: Some(BufWriter::new(file)),
        })
    }

    /// The destination.
    pub fn path(&self) -> &Path {
        &self.dest
    }

    /// Flushes, syncs and renames the file over its destination. On an error (a full disk,
    /// a directory in the destination's place) the temporary file is removed and the
    /// destination keeps what it had.
    pub fn commit(mut self) -> anyhow::Result<()> {
        let out = self.out.take().expect("an AtomicFile is committed once");
        // On every error the `NamedTempFile` is dropped, which removes the temporary file.
        let renamed = out
            .into_inner()
            .map_err(|e| e.into_error())
            .and_then(|file| file.as_file().sync_all().map(|()| file))
            .and_then(|file| file.persist(&self.dest).map_err(|e| e.error));
        forget_live(&self.tmp);
        renamed
            .map(drop)
            .with_context(|| format!("cannot write '{}'", self.dest.display()))
    }
}

impl Write for AtomicFile {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        self.out.as_mut().expect("not yet committed").write(buf)
    }

    fn flush(&mut self) -> io::Result<()> {
        self.out.as_mut().expect("not yet committed").flush()
    }
}

impl Drop for AtomicFile {
    fn drop(&mut self) {
        // Not committed: dropping the file removes it, and the destination keeps what it had.
        if let Some(out) = self.out.take() {
            drop(out);
            forget_live(&self.tmp);
        }
    }
}

fn forget_live(tmp: &Path) {
    live().retain(|p| p != tmp);
}

/// Writes `bytes` to `dest` atomically.
pub fn write(dest: &Path, bytes: &[u8]) -> anyhow::Result<()> {
    let mut file = AtomicFile::create(dest)?;
    file.write_all(bytes)
        .with_context(|| format!("cannot write '{}'", dest.display()))?;
    file.commit()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names(dir: &Path) -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }

    #[test]
    fn a_committed_file_replaces_the_destination_and_leaves_no_temporary() {
        let dir = tempfile::tempdir().unwrap();
        let dest = dir.path().join("out.csv");
        std::fs::write(&dest, "old").unwrap();
        write(&dest, b"new").unwrap();
        assert_eq!(std::fs::read_to_string(&dest).unwrap(), "new");
        assert_eq!(names(dir.path()), ["out.csv"]);
    }

    #[test]
    fn a_file_dropped_before_its_commit_leaves_the_destination_as_it_was() {
        let dir = tempfile::tempdir().unwrap();
        let dest = dir.path().join("out.csv");
        std::fs::write(&dest, "old").unwrap();
        let mut f = AtomicFile::create(&dest).unwrap();
        f.write_all(b"half a fi").unwrap();
        assert_eq!(
            names(dir.path()).len(),
            2,
            "the temporary file exists while writing"
        );
        assert!(names(dir.path()).iter().any(|n| is_temporary(n)));
        drop(f);
        assert_eq!(std::fs::read_to_string(&dest).unwrap(), "old");
        assert_eq!(names(dir.path()), ["out.csv"]);
    }

    #[test]
    #[cfg(unix)]
    fn a_committed_file_has_the_permissions_a_plain_create_gives() {
        use std::os::unix::fs::PermissionsExt;
        let dir = tempfile::tempdir().unwrap();
        let plain = dir.path().join("plain.csv");
        std::fs::File::create(&plain).unwrap();
        let dest = dir.path().join("out.csv");
        write(&dest, b"new").unwrap();
        let mode = |p: &Path| std::fs::metadata(p).unwrap().permissions().mode() & 0o777;
        assert_eq!(mode(&dest), mode(&plain));
    }

    #[test]
    fn a_commit_over_a_directory_fails_and_leaves_no_temporary() {
        let dir = tempfile::tempdir().unwrap();
        let dest = dir.path().join("chart.png");
        std::fs::create_dir(&dest).unwrap();
        let err = format!("{:#}", write(&dest, b"png").unwrap_err());
        assert!(err.contains("cannot write"), "{err}");
        assert_eq!(names(dir.path()), ["chart.png"]);
        assert!(dest.is_dir());
    }

    #[test]
    fn a_missing_directory_is_an_error_naming_the_destination() {
        let dir = tempfile::tempdir().unwrap();
        let dest = dir.path().join("no/such/out.csv");
        let err = format!("{:#}", write(&dest, b"x").unwrap_err());
        assert!(
            err.contains("cannot write") && err.contains("out.csv"),
            "{err}"
        );
    }
}
