//! Where a command's output file goes. A regular file (or a new one) is written through
//! [`AtomicFile`]: whole or not at all, so a failed or interrupted run leaves the earlier file
//! as it was. A path that exists and is not a regular file (`/dev/stdout`, `/dev/null`,
//! `/dev/full`, a named pipe) is written directly: it holds no earlier contents to keep, and a
//! rename would replace the device itself.

use std::fs::File;
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};

use anyhow::Context;

use crate::output::atomic::AtomicFile;

/// An output file being written; see the module docs.
#[derive(Debug)]
pub enum Sink {
    /// A regular file, renamed into place by [`Sink::commit`].
    Atomic(AtomicFile),
    /// A device or pipe, written as it goes.
    Stream {
        /// The path.
        path: PathBuf,
        /// The open device.
        out: BufWriter<File>,
    },
}

impl Sink {
    /// Starts writing `path`. Errors name it.
    pub fn create(path: &Path) -> anyhow::Result<Sink> {
        let special = std::fs::metadata(path).is_ok_and(|m| !m.is_file() && !m.is_dir());
        if !special {
            return Ok(Sink::Atomic(AtomicFile::create(path)?));
        }
        let file = std::fs::OpenOptions::new()
            .write(true)
            .open(path)
            .with_context(|| format!("cannot write '{}'", path.display()))?;
        Ok(Sink::Stream {
            path: path.to_owned(),
            out: BufWriter::new(file),
        })
    }

    /// The destination.
    pub fn path(&self) -> &Path {
        match self {
            Sink::Atomic(file) => file.path(),
            Sink::Stream { path, .. } => path,
        }
    }

    /// Completes the file: renames it into place, or flushes the device.
    pub fn commit(self) -> anyhow::Result<()> {
        match self {
            Sink::Atomic(file) => file.commit(),
            Sink::Stream { path, mut out } => out
                .flush()
                .with_context(|| format!("cannot write '{}'", path.display())),
        }
    }
}

impl Write for Sink {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        match self {
            Sink::Atomic(file) => file.write(buf),
            Sink::Stream { out, .. } => out.write(buf),
        }
    }

    fn flush(&mut self) -> io::Result<()> {
        match self {
            Sink::Atomic(file) => file.flush(),
            Sink::Stream { out, .. } => out.flush(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_regular_file_is_replaced_only_on_commit() {
        let dir = tempfile::tempdir().unwrap();
        let dest = dir.path().join("out.csv");
        std::fs::write(&dest, "old").unwrap();
        let mut sink = Sink::create(&dest).unwrap();
        sink.write_all(b"new").unwrap();
        assert_eq!(std::fs::read_to_string(&dest).unwrap(), "old");
        sink.commit().unwrap();
        assert_eq!(std::fs::read_to_string(&dest).unwrap(), "new");
    }

    #[test]
    fn a_device_is_written_in_place_and_stays_a_device() {
        let mut sink = Sink::create(Path::new("/dev/null")).unwrap();
        assert!(matches!(sink, Sink::Stream { .. }));
        sink.write_all(b"gone").unwrap();
        sink.commit().unwrap();
        assert!(!std::fs::metadata("/dev/null").unwrap().is_file());
    }
}
