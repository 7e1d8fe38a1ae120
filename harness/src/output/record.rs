//! The record of what bench-sph wrote in a directory: `DIR/bench-sph-files.json`.
//!
//! Every command that writes a directory (`sweep`, `merge`, `report`, `trace`, `render
//! --frames`, `validate`) enters each file's name here, with the command, **before** it
//! creates the file, so a command killed at any moment leaves a record that covers whatever
//! it wrote. `--force` replaces or removes only files the record gives to the command (see
//! [`super::claim`]); a file the record does not name is never replaced or removed, whatever
//! its name, size or contents. Nothing is guessed from names or bytes.
//!
//! The file, written whole through [`super::atomic`]:
//!
//! ```json
//! {
//!   "about": "The files bench-sph wrote in this directory, and the command that wrote each …",
//!   "files": {
//!     "REPORT.md": "report",
//!     "meta.json": "sweep",
//!     "summary.csv": "sweep",
//!     "trials.csv": "sweep"
//!   }
//! }
//! ```
//!
//! Names are of the directory's own entries (never a path into a subdirectory), sorted. The
//! record names neither itself nor the lock file ([`super::lock`]). It is changed only under
//! the directory's lock, read from disk each time ([`add`], [`remove`]), so two commands of
//! one process (a sweep drawing its report) never undo each other's entries.

use std::collections::BTreeMap;
use std::fmt;
use std::path::Path;

use anyhow::Context;
use serde::{Deserialize, Serialize};

use crate::io::capped;

/// The record's file name.
pub const RECORD_FILE: &str = "bench-sph-files.json";

/// What the record says of itself, for whoever opens it.
const ABOUT: &str = "The files bench-sph wrote in this directory, and the command that wrote \
                     each. With --force a command replaces or removes only its own files \
                     listed here; no other file is ever replaced or removed.";

/// A command that writes a directory.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Command {
    /// `bench-sph sweep`: `trials.csv`, `summary.csv`, `meta.json`.
    Sweep,
    /// `bench-sph merge`: the same, and `references.csv`.
    Merge,
    /// `bench-sph report` (also as the end of a sweep): `REPORT.md`, charts, copied timelines.
    Report,
    /// `bench-sph trace`: `trace.json`, `timeline.png`, `stats.csv`, `meta.json`.
    Trace,
    /// `bench-sph render --frames`: `frame_00000.png`, ….
    Render,
    /// `bench-sph validate`: `surge_front.csv`, `column_height.csv`, `validation.png`.
    Validate,
}

impl Command {
    /// The subcommand's name, e.g. `sweep`, as the record writes it.
    pub fn name(self) -> &'static str {
        match self {
            Command::Sweep => "sweep",
            Command::Merge => "merge",
            Command::Report => "report",
            Command::Trace => "trace",
            Command::Render => "render",
            Command::Validate => "validate",
        }
    }

    /// The command named by [`Command::name`].
    pub fn from_name(name: &str) -> Option<Command> {
        [
            Command::Sweep,
            Command::Merge,
            Command::Report,
            Command::Trace,
            Command::Render,
            Command::Validate,
        ]
        .into_iter()
        .find(|c| c.name() == name)
    }
}

/// `bench-sph sweep`, as messages name a command.
impl fmt::Display for Command {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "bench-sph {}", self.name())
    }
}

/// A directory's record: which command wrote each file.
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Record {
    /// What the file is ([`ABOUT`]; not read back).
    #[serde(default, skip_deserializing)]
    about: String,
    /// File name → the command that wrote it.
    pub files: BTreeMap<String, Command>,
}

impl Record {
    /// The command that wrote `name`, if the record names it.
    pub fn writer(&self, name: &str) -> Option<Command> {
        self.files.get(name).copied()
    }

    /// Whether the record names a file of `command`.
    pub fn has(&self, command: Command) -> bool {
        self.files.values().any(|&c| c == command)
    }

    /// `dir`'s record, or `None` when it has none. A record that cannot be read is an error:
    /// without it nothing in the directory could be told from a user's file.
    pub fn read(dir: &Path) -> anyhow::Result<Option<Record>> {
        let path = dir.join(RECORD_FILE);
        let Some(bytes) = capped::read_if_exists(&path, capped::RECORD)? else {
            return Ok(None);
        };
        serde_json::from_slice(&bytes).map(Some).with_context(|| {
            format!(
                "'{}' is not bench-sph's record of the files it wrote (remove it only if \
                 nothing in '{}' is bench-sph's)",
                path.display(),
                dir.display()
            )
        })
    }

    fn write(&self, dir: &Path) -> anyhow::Result<()> {
        let record = Record {
            about: ABOUT.to_owned(),
            files: self.files.clone(),
        };
        let mut text = serde_json::to_string_pretty(&record)?;
        text.push('\n');
        super::atomic::write(&dir.join(RECORD_FILE), text.as_bytes())
    }
}

/// Records that `command` writes `names` in `dir` (call it before creating them, holding
/// `dir`'s lock). Writes the record only when something changed.
pub fn add<S: AsRef<str>>(dir: &Path, command: Command, names: &[S]) -> anyhow::Result<()> {
    let mut record = Record::read(dir)?.unwrap_or_default();
    let mut changed = false;
    for name in names {
        let name = name.as_ref();
        if record.files.get(name) != Some(&command) {
            record.files.insert(name.to_owned(), command);
            changed = true;
        }
    }
    if changed {
        record.write(dir)?;
    }
    Ok(())
}

/// Takes `names` out of `dir`'s record (files removed, or never written).
pub fn remove<S: AsRef<str>>(dir: &Path, names: &[S]) -> anyhow::Result<()> {
    let Some(mut record) = Record::read(dir)? else {
        return Ok(());
    };
    let before = record.files.len();
    for name in names {
        record.files.remove(name.as_ref());
    }
    if record.files.len() != before {
        record.write(dir)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn entries_are_added_and_removed_and_read_back_with_their_command() {
        let dir = tempfile::tempdir().unwrap();
        assert_eq!(Record::read(dir.path()).unwrap(), None);
        add(dir.path(), Command::Sweep, &["trials.csv", "meta.json"]).unwrap();
        add(dir.path(), Command::Report, &["REPORT.md"]).unwrap();
        let record = Record::read(dir.path()).unwrap().unwrap();
        assert_eq!(record.writer("meta.json"), Some(Command::Sweep));
        assert_eq!(record.writer("REPORT.md"), Some(Command::Report));
        assert_eq!(record.writer("notes.txt"), None);
        remove(dir.path(), &["REPORT.md"]).unwrap();
        let record = Record::read(dir.path()).unwrap().unwrap();
        assert!(!record.has(Command::Report) && record.has(Command::Sweep));
    }

    #[test]
    fn the_record_is_json_that_says_what_it_is() {
        let dir = tempfile::tempdir().unwrap();
        add(dir.path(), Command::Trace, &["stats.csv"]).unwrap();
        let text = std::fs::read_to_string(dir.path().join(RECORD_FILE)).unwrap();
        let value: serde_json::Value = serde_json::from_str(&text).unwrap();
        assert_eq!(value["files"]["stats.csv"], "trace");
        assert!(value["about"].as_str().unwrap().contains("--force"));
    }

    #[test]
    fn a_garbled_record_is_an_error_not_an_empty_record() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(
            dir.path().join(RECORD_FILE),
            "{\"files\": {\"a\": \"paint\"}}",
        )
        .unwrap();
        let err = format!("{:#}", Record::read(dir.path()).unwrap_err());
        assert!(err.contains("is not bench-sph's record"), "{err}");
    }

    #[test]
    fn command_names_round_trip() {
        for c in [Command::Sweep, Command::Render, Command::Validate] {
            assert_eq!(Command::from_name(c.name()), Some(c));
        }
        assert_eq!(Command::Trace.to_string(), "bench-sph trace");
    }
}
