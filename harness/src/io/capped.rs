//! The one way bench-sph reads a file of a results, trace or output directory: **regular files
//! only**, and **at most a cap per kind of file** ([`Kind`]).
//!
//! - A FIFO, a device, a socket or a directory — named directly or through a symbolic link —
//!   is refused before it is read, so `trials.csv → /dev/zero` fails at once instead of
//!   filling memory, and a FIFO fails at once instead of blocking. The file is opened
//!   non-blocking and checked again once open, so one swapped in between cannot block either.
//! - A file larger than its kind's cap is refused from its size, before a byte is read, and a
//!   file that grows past the cap while it is read stops the read there.
//!
//! Every refusal names the file and, for the size, the cap: `'D/trials.csv' is larger than
//! 1 GiB, the most a trials.csv may be`. (`--init` reads a CSV the user names, which may well
//! be a pipe: it keeps its own line bounds, [`super::bounded`].)

use std::fs::{File, FileType, Metadata};
use std::io::{self, Read};
use std::path::Path;

use anyhow::Context;

const KIB: u64 = 1024;
const MIB: u64 = 1024 * KIB;
const GIB: u64 = 1024 * MIB;

/// A kind of file, and the most bytes bench-sph reads of it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Kind {
    /// How messages name the kind, e.g. `trials.csv`.
    pub name: &'static str,
    /// The most bytes accepted.
    pub cap: u64,
}

/// A results directory's `trials.csv`: a trial row is about 200 bytes, so 1 GiB holds five
/// million runs — 1 000 000 cells (the most a sweep may plan, `crate::limits::MAX_CELLS`) at
/// the default 5 rounds.
pub const TRIALS_CSV: Kind = Kind {
    name: "trials.csv",
    cap: GIB,
};

/// A results directory's `summary.csv` (and a merge's `references.csv`, of the same columns):
/// a row is about 340 bytes and under 512 even with a failure's reason, so 1 GiB holds a grid
/// row and a confirmation row for each of 1 000 000 cells.
pub const SUMMARY_CSV: Kind = Kind {
    name: "summary.csv",
    cap: GIB,
};

/// A results directory's `meta.json`: a sweep's is a few KiB; a partial merge's lists every
/// missing cell (a label under 128 bytes, at most 1 000 000 of them) and every shard's
/// sessions (at most 1024 shards), well under 256 MiB.
pub const META_JSON: Kind = Kind {
    name: "meta.json",
    cap: 256 * MIB,
};

/// A directory's record of the files bench-sph wrote there
/// ([`crate::output::record::RECORD_FILE`]): an entry is under 64 bytes, so 64 MiB records a
/// million files (PNG frames are the most numerous).
pub const RECORD: Kind = Kind {
    name: "record of bench-sph's files",
    cap: 64 * MIB,
};

/// A directory's lock file ([`crate::output::lock::LOCK_FILE`]): a command's name and a PID.
pub const LOCK: Kind = Kind {
    name: "lock file",
    cap: 4 * KIB,
};

/// A trace's `stats.csv`: a row per worker (at most 1024), per pass and the total, each under
/// 128 bytes.
pub const TRACE_STATS_CSV: Kind = Kind {
    name: "trace's stats.csv",
    cap: MIB,
};

/// A trace's `meta.json`: its configuration and totals, under 1 KiB.
pub const TRACE_META_JSON: Kind = Kind {
    name: "trace's meta.json",
    cap: MIB,
};

/// A trace's `timeline.png`, which a report copies: 1600 pixels wide and 112 pixels a worker
/// track (a timeline of 1024 workers is 115 000 pixels high, 550 MB as raw RGB, and its PNG,
/// mostly blank, compresses to a small part of that).
pub const TIMELINE_PNG: Kind = Kind {
    name: "timeline.png",
    cap: 256 * MIB,
};

/// Why a file is not read.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum Refused {
    /// Not a regular file.
    #[error("'{path}' is {what}, not a regular file: bench-sph reads only regular files here")]
    NotRegular {
        /// The path, as given.
        path: String,
        /// What it is, e.g. `a FIFO (named pipe)`.
        what: String,
    },
    /// Larger than its kind's cap.
    #[error("'{path}' is larger than {cap}, the most a {kind} may be")]
    TooLarge {
        /// The path, as given.
        path: String,
        /// The cap, e.g. `1 GiB`.
        cap: String,
        /// The kind's name.
        kind: &'static str,
    },
}

/// A file open for reading, which fails with [`Refused::TooLarge`] (inside an
/// [`io::Error`] of kind `InvalidData`) once more than its cap has been read.
#[derive(Debug)]
pub struct Capped {
    file: File,
    /// Bytes that may still be read.
    left: u64,
    refused: Refused,
}

impl Read for Capped {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        // One byte more than allowed tells a file at its cap from one beyond it.
        let room = usize::try_from(self.left.saturating_add(1))
            .unwrap_or(usize::MAX)
            .min(buf.len());
        let got = self.file.read(&mut buf[..room])?;
        if got as u64 > self.left {
            return Err(io::Error::new(
                io::ErrorKind::InvalidData,
                self.refused.clone(),
            ));
        }
        self.left -= got as u64;
        Ok(got)
    }
}

/// Opens `path` to read it as a `kind`; `Ok(None)` when there is no such file. Refuses what is
/// not a regular file and a file beyond the cap (see the module docs).
pub fn open_if_exists(path: &Path, kind: Kind) -> anyhow::Result<Option<Capped>> {
    let context = || format!("cannot read '{}'", path.display());
    let meta = match std::fs::metadata(path) {
        Ok(meta) => meta,
        Err(e) if e.kind() == io::ErrorKind::NotFound => return Ok(None),
        Err(e) => return Err(e).with_context(context),
    };
    check(path, &meta, kind)?;
    let file = open_nonblocking(path).with_context(context)?;
    // Again on what was opened: the path may name something else by now.
    check(path, &file.metadata().with_context(context)?, kind)?;
    Ok(Some(Capped {
        file,
        left: kind.cap,
        refused: too_large(path, kind),
    }))
}

/// [`open_if_exists`], with a missing file an error.
pub fn open(path: &Path, kind: Kind) -> anyhow::Result<Capped> {
    open_if_exists(path, kind)?
        .with_context(|| format!("cannot read '{}': no such file", path.display()))
}

/// The bytes of `path`, read as a `kind`; `Ok(None)` when there is no such file.
pub fn read_if_exists(path: &Path, kind: Kind) -> anyhow::Result<Option<Vec<u8>>> {
    let Some(mut file) = open_if_exists(path, kind)? else {
        return Ok(None);
    };
    let mut bytes = Vec::new();
    file.read_to_end(&mut bytes)
        .map_err(|e| io_error(e, path))?;
    Ok(Some(bytes))
}

/// The bytes of `path`, read as a `kind`.
pub fn read(path: &Path, kind: Kind) -> anyhow::Result<Vec<u8>> {
    read_if_exists(path, kind)?
        .with_context(|| format!("cannot read '{}': no such file", path.display()))
}

/// The text of `path`, read as a `kind`.
pub fn read_to_string(path: &Path, kind: Kind) -> anyhow::Result<String> {
    String::from_utf8(read(path, kind)?)
        .with_context(|| format!("cannot read '{}': it is not UTF-8 text", path.display()))
}

/// An error of reading `path`: the [`Refused`] inside it where that is what it holds, else
/// the I/O error with the file's name.
pub fn io_error(err: io::Error, path: &Path) -> anyhow::Error {
    match err.get_ref().and_then(|e| e.downcast_ref::<Refused>()) {
        Some(refused) => refused.clone().into(),
        None => anyhow::Error::new(err).context(format!("cannot read '{}'", path.display())),
    }
}

fn check(path: &Path, meta: &Metadata, kind: Kind) -> Result<(), Refused> {
    if !meta.is_file() {
        let mut what = describe(meta.file_type()).to_owned();
        if std::fs::symlink_metadata(path).is_ok_and(|m| m.file_type().is_symlink()) {
            what.push_str(" (through a symbolic link)");
        }
        return Err(Refused::NotRegular {
            path: path.display().to_string(),
            what,
        });
    }
    if meta.len() > kind.cap {
        return Err(too_large(path, kind));
    }
    Ok(())
}

fn too_large(path: &Path, kind: Kind) -> Refused {
    Refused::TooLarge {
        path: path.display().to_string(),
        cap: bytes_text(kind.cap),
        kind: kind.name,
    }
}

/// What a file that is not a regular file is, in words.
fn describe(file_type: FileType) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if file_type.is_fifo() {
            return "a FIFO (named pipe)";
        }
        if file_type.is_char_device() {
            return "a character device";
        }
        if file_type.is_block_device() {
            return "a block device";
        }
        if file_type.is_socket() {
            return "a socket";
        }
    }
    if file_type.is_dir() {
        "a directory"
    } else {
        "something else"
    }
}

/// Opens `path` read-only without waiting: opening a FIFO that has no writer would otherwise
/// block (a regular file ignores the flag).
fn open_nonblocking(path: &Path) -> io::Result<File> {
    let mut options = std::fs::OpenOptions::new();
    options.read(true);
    #[cfg(unix)]
    {
        use std::os::unix::fs::OpenOptionsExt;
        options.custom_flags(nix::libc::O_NONBLOCK);
    }
    options.open(path)
}

/// A number of bytes as the caps are written: `4 KiB`, `64 MiB`, `1 GiB`.
pub fn bytes_text(bytes: u64) -> String {
    match bytes {
        b if b >= GIB && b % GIB == 0 => format!("{} GiB", b / GIB),
        b if b >= MIB && b % MIB == 0 => format!("{} MiB", b / MIB),
        b if b >= KIB && b % KIB == 0 => format!("{} KiB", b / KIB),
        b => format!("{b} bytes"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const TINY: Kind = Kind {
        name: "tiny file",
        cap: 8,
    };

    #[test]
    fn a_file_within_its_cap_reads_whole_and_a_missing_one_is_none() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a");
        std::fs::write(&path, "12345678").unwrap();
        assert_eq!(read(&path, TINY).unwrap(), b"12345678");
        assert!(
            read_if_exists(&dir.path().join("b"), TINY)
                .unwrap()
                .is_none()
        );
        let err = format!("{:#}", read(&dir.path().join("b"), TINY).unwrap_err());
        assert!(err.contains("no such file"), "{err}");
    }

    #[test]
    fn a_file_beyond_its_cap_is_refused_naming_the_cap() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a");
        std::fs::write(&path, "123456789").unwrap();
        let err = read(&path, TINY).unwrap_err().to_string();
        assert_eq!(
            err,
            format!(
                "'{}' is larger than 8 bytes, the most a tiny file may be",
                path.display()
            )
        );
    }

    #[test]
    fn a_file_that_grows_past_its_cap_while_read_stops_there() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a");
        std::fs::write(&path, "1234").unwrap();
        let mut file = open(&path, TINY).unwrap();
        std::fs::write(&path, "1234567890").unwrap();
        let err = file.read_to_end(&mut Vec::new()).unwrap_err();
        let err = io_error(err, &path).to_string();
        assert!(err.contains("is larger than 8 bytes"), "{err}");
    }

    #[cfg(unix)]
    #[test]
    fn a_device_or_a_directory_is_refused_at_once_even_through_a_link() {
        let dir = tempfile::tempdir().unwrap();
        let link = dir.path().join("trials.csv");
        std::os::unix::fs::symlink("/dev/zero", &link).unwrap();
        let err = read(&link, TRIALS_CSV).unwrap_err().to_string();
        assert!(
            err.contains("is a character device (through a symbolic link), not a regular file"),
            "{err}"
        );
        let err = read(dir.path(), TRIALS_CSV).unwrap_err().to_string();
        assert!(err.contains("is a directory"), "{err}");
    }

    #[cfg(unix)]
    #[test]
    fn a_fifo_is_refused_without_blocking() {
        let dir = tempfile::tempdir().unwrap();
        let fifo = dir.path().join("summary.csv");
        let made = std::process::Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .is_ok_and(|s| s.success());
        if !made {
            return; // No mkfifo here: the integration tests cover it where there is one.
        }
        let err = read(&fifo, SUMMARY_CSV).unwrap_err().to_string();
        assert!(err.contains("is a FIFO (named pipe)"), "{err}");
    }

    #[test]
    fn sizes_are_written_in_the_largest_whole_unit() {
        assert_eq!(bytes_text(GIB), "1 GiB");
        assert_eq!(bytes_text(256 * MIB), "256 MiB");
        assert_eq!(bytes_text(4 * KIB), "4 KiB");
        assert_eq!(bytes_text(1000), "1000 bytes");
    }
}
