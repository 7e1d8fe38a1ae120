//! Which files in an output directory a command may replace: those the directory's record
//! ([`super::record`]) gives to it, and no other.
//!
//! Every command that writes a directory (`sweep --out`, `merge --out`, `report --out`,
//! `trace --out`, `render --frames`, `validate --out`) claims it first with [`claim`]:
//! - a missing directory is created, and the directory is locked for as long as the command
//!   writes ([`super::lock`]): a second writer, of any command, is refused naming the first;
//! - its entries are sorted by the record: the command's **own** files (the record names the
//!   command, or one the command replaces: [`Owner::replaces`]), files it leaves alone
//!   ([`Owner::tolerates`]: a sweep's results beside its report, say), and everything else —
//!   every file the record does not name, whatever its name, size or contents, and the files
//!   of other commands — which is **foreign**;
//! - a directory holding foreign entries is refused, naming them, unless `--force`; with
//!   `--force` they stay untouched, and writing over one is still an error
//!   ([`Claimed::check_writable`]): `--force` replaces only the command's own files. A
//!   directory without a record (written by an older bench-sph, or by hand) has nothing of
//!   the command's own: it is refused unless `--force`, which then writes beside everything;
//! - the command records each file before creating it ([`Claimed::record`]), and afterwards
//!   removes its own recorded files that this run did not write again
//!   ([`Claimed::remove_stale`]: old frames, old charts).
//!
//! The record, the lock files and [`super::atomic`]'s temporary files are never counted.

use std::collections::HashSet;
use std::path::{Path, PathBuf};

use anyhow::{Context, bail};

use super::atomic::is_temporary;
use super::lock::{self, DirLock, LEGACY_LOCK_FILE, LOCK_FILE};
use super::record::{self, Command, RECORD_FILE, Record};

/// A command, and what it may do with a directory's entries.
pub struct Owner<'a> {
    /// The command.
    pub command: Command,
    /// The option that names the directory, e.g. `--out`.
    pub option: &'a str,
    /// Other commands whose recorded files this one replaces with `--force` (a new sweep
    /// replaces an earlier sweep's or merge's results and the report drawn there).
    pub replaces: &'a [Command],
    /// Commands whose recorded files stay beside this command's output, neither replaced nor
    /// refused (a report in a sweep's directory leaves the sweep's files alone).
    pub tolerates: &'a [Command],
    /// Whether an entry the record does not name may stay beside the output, neither
    /// replaced nor refused (a trace directory inside a sweep's; the report's own input files).
    pub tolerates_unrecorded: &'a dyn Fn(&Path) -> bool,
    /// The files the command will write, where known before it starts: each is checked
    /// ([`Claimed::check_writable`]) before anything is created, the lock file included.
    pub writes: &'a [&'a str],
}

/// Tolerates nothing: for [`Owner::tolerates_unrecorded`].
pub fn nothing(_: &Path) -> bool {
    false
}

/// An entry a command may not replace.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Foreign {
    /// Its name in the directory.
    pub name: String,
    /// The command the record says wrote it; `None` when the record does not name it.
    pub writer: Option<Command>,
    /// Whether it is a directory.
    pub is_dir: bool,
}

/// A directory a command holds and may write into.
#[derive(Debug, Clone)]
pub struct Claimed {
    dir: PathBuf,
    command: Command,
    /// What the directory held when it was claimed.
    survey: Survey,
    /// Names the command may write: its earlier files and those it has recorded since.
    mine: HashSet<String>,
    lock: DirLock,
}

/// What a directory holds, for an [`Owner`]: its own recorded files (or those of commands it
/// replaces) with their writers, the entries it may not replace, and whether there was a
/// record at all.
#[derive(Debug, Clone)]
struct Survey {
    earlier: Vec<(String, Command)>,
    foreign: Vec<Foreign>,
    had_record: bool,
}

/// Locks and claims `dir` for `owner`; see the module docs.
pub fn claim(dir: &Path, owner: &Owner<'_>, force: bool) -> anyhow::Result<Claimed> {
    if dir.exists() && !dir.is_dir() {
        bail!(
            "{} '{}' exists and is not a directory",
            owner.option,
            dir.display()
        );
    }
    std::fs::create_dir_all(dir)
        .with_context(|| format!("cannot create directory '{}'", dir.display()))?;
    let check = |survey: &Survey| -> anyhow::Result<()> {
        refuse_foreign(dir, owner, survey, force)?;
        for name in owner.writes {
            writable(dir, owner.command, survey, &survey.mine(), name)?;
        }
        Ok(())
    };
    if std::fs::symlink_metadata(dir.join(LOCK_FILE)).is_err() {
        // Not a directory bench-sph writes yet: refuse before creating a lock file in it, so
        // that a refused command leaves nothing behind. (The lock file is never deleted.)
        check(&survey(dir, owner)?)?;
    }
    let lock = lock::acquire(dir, owner.command)?;
    // Again under the lock, which makes it authoritative.
    let survey = survey(dir, owner)?;
    check(&survey)?;
    Ok(Claimed {
        dir: dir.to_path_buf(),
        command: owner.command,
        mine: survey.mine(),
        survey,
        lock,
    })
}

impl Survey {
    /// The names of the earlier files.
    fn mine(&self) -> HashSet<String> {
        self.earlier.iter().map(|(n, _)| n.clone()).collect()
    }
}

/// `dir/name`, unless something `command` may not replace is there: a directory, or a file
/// the record does not give to it (`mine`, the names it may write).
fn writable(
    dir: &Path,
    command: Command,
    survey: &Survey,
    mine: &HashSet<String>,
    name: &str,
) -> anyhow::Result<PathBuf> {
    let path = dir.join(name);
    let meta = match std::fs::symlink_metadata(&path) {
        Ok(meta) => meta,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(path),
        Err(e) => return Err(e).with_context(|| format!("cannot write '{}'", path.display())),
    };
    if meta.is_file() && mine.contains(name) {
        return Ok(path);
    }
    if meta.is_dir() {
        bail!(
            "cannot write '{}': a directory of that name is in the way (nothing was written; \
             move it, or write elsewhere)",
            path.display()
        );
    }
    let why = match survey.foreign.iter().find(|f| f.name == name) {
        Some(Foreign {
            writer: Some(c), ..
        }) => format!("the record says {c} wrote it"),
        _ => format!("no record in '{}' says it did", dir.display()),
    };
    bail!(
        "cannot write '{}': it exists and was not written by {command} ({why}); --force \
         replaces only that command's own files: move it away, or write elsewhere",
        path.display()
    )
}

/// Whether a directory entry is bench-sph's own bookkeeping, never counted: the record, the
/// lock files, temporary files.
pub fn is_bookkeeping(name: &str) -> bool {
    name == RECORD_FILE || name == LOCK_FILE || name == LEGACY_LOCK_FILE || is_temporary(name)
}

fn survey(dir: &Path, owner: &Owner<'_>) -> anyhow::Result<Survey> {
    let record = Record::read(dir)?;
    let read = std::fs::read_dir(dir)
        .with_context(|| format!("cannot read directory '{}'", dir.display()))?;
    let mut names = Vec::new();
    for entry in read {
        let entry = entry.with_context(|| format!("cannot read directory '{}'", dir.display()))?;
        names.push(entry.file_name().to_string_lossy().into_owned());
    }
    names.sort();
    let mut survey = Survey {
        earlier: Vec::new(),
        foreign: Vec::new(),
        had_record: record.is_some(),
    };
    for name in names.into_iter().filter(|n| !is_bookkeeping(n)) {
        let path = dir.join(&name);
        let Ok(meta) = std::fs::symlink_metadata(&path) else {
            continue; // Gone since it was listed.
        };
        let writer = record.as_ref().and_then(|r| r.writer(&name));
        match writer {
            // Only a plain file is still the one the command wrote (a link or a directory in
            // its place is someone else's).
            Some(c) if (c == owner.command || owner.replaces.contains(&c)) && meta.is_file() => {
                survey.earlier.push((name, c));
                continue;
            }
            Some(c) if owner.tolerates.contains(&c) => continue,
            None if (owner.tolerates_unrecorded)(&path) => continue,
            _ => {}
        }
        survey.foreign.push(Foreign {
            name,
            writer,
            is_dir: path.is_dir(),
        });
    }
    Ok(survey)
}

fn refuse_foreign(
    dir: &Path,
    owner: &Owner<'_>,
    survey: &Survey,
    force: bool,
) -> anyhow::Result<()> {
    if survey.foreign.is_empty() || force {
        return Ok(());
    }
    let no_record = match survey.had_record {
        true => String::new(),
        false => format!(
            "; it has no {RECORD_FILE}, bench-sph's record of the files it wrote, so none of \
             them counts as bench-sph's"
        ),
    };
    bail!(
        "{} '{}' holds files that {} did not write ({}); choose a new or empty directory, or \
         pass --force to write beside them (they stay untouched: --force replaces only {}'s \
         own files){no_record}",
        owner.option,
        dir.display(),
        owner.command,
        list(&survey.foreign),
        owner.command
    )
}

/// Up to three names (a directory with a `/`, another command's file with its writer), then
/// how many more.
fn list(foreign: &[Foreign]) -> String {
    let mut names: Vec<String> = foreign
        .iter()
        .take(3)
        .map(|f| {
            let slash = if f.is_dir { "/" } else { "" };
            match f.writer {
                Some(c) => format!("'{}{slash}' of {c}", f.name),
                None => format!("'{}{slash}'", f.name),
            }
        })
        .collect();
    if foreign.len() > 3 {
        names.push(format!("and {} more", foreign.len() - 3));
    }
    names.join(", ")
}

impl Claimed {
    /// The directory.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// The directory's lock, to hold beyond this claim.
    pub fn lock(&self) -> DirLock {
        self.lock.clone()
    }

    /// The command's own recorded files (or those of commands it replaces) that were there
    /// when it claimed the directory, with the command that wrote each.
    pub fn earlier(&self) -> &[(String, Command)] {
        &self.survey.earlier
    }

    /// Entries it may not replace (non-empty only with `--force`).
    pub fn foreign(&self) -> &[Foreign] {
        &self.survey.foreign
    }

    /// Whether the directory had a record of bench-sph's files when it was claimed.
    pub fn had_record(&self) -> bool {
        self.survey.had_record
    }

    /// `dir/name`, unless something the command may not replace is there: a directory, or a
    /// file the record does not give to the command (or to one it replaces).
    pub fn check_writable(&self, name: &str) -> anyhow::Result<PathBuf> {
        writable(&self.dir, self.command, &self.survey, &self.mine, name)
    }

    /// Records that the command writes `names` (call it before creating them).
    pub fn record<S: AsRef<str>>(&mut self, names: &[S]) -> anyhow::Result<()> {
        record::add(&self.dir, self.command, names)?;
        self.mine
            .extend(names.iter().map(|n| n.as_ref().to_owned()));
        Ok(())
    }

    /// Removes every earlier file ([`Claimed::earlier`]: the command's own and those of the
    /// commands it replaces) and takes it out of the record; returns them.
    pub fn remove_earlier(&mut self) -> anyhow::Result<Vec<PathBuf>> {
        let names: Vec<String> = self.survey.earlier.iter().map(|(n, _)| n.clone()).collect();
        let removed = self.remove_files(&names)?;
        self.survey.earlier.clear();
        Ok(removed)
    }

    /// Removes the command's own recorded files that this run did not write (`written`), and
    /// returns them. A name the record gives to the command whose file is gone, or is no
    /// longer a plain file (left alone), leaves the record too.
    pub fn remove_stale(&mut self, written: &[PathBuf]) -> anyhow::Result<Vec<PathBuf>> {
        let written: HashSet<&std::ffi::OsStr> =
            written.iter().filter_map(|p| p.file_name()).collect();
        let record = Record::read(&self.dir)?.unwrap_or_default();
        let stale: Vec<String> = record
            .files
            .iter()
            .filter(|&(name, &c)| {
                c == self.command && !written.contains(std::ffi::OsStr::new(name))
            })
            .map(|(name, _)| name.clone())
            .collect();
        self.remove_files(&stale)
    }

    /// Removes those of `names` that are plain files, forgets all of them, returns the
    /// removed files.
    fn remove_files(&mut self, names: &[String]) -> anyhow::Result<Vec<PathBuf>> {
        let mut removed = Vec::new();
        for name in names {
            let path = self.dir.join(name);
            if !std::fs::symlink_metadata(&path).is_ok_and(|m| m.is_file()) {
                continue;
            }
            match std::fs::remove_file(&path) {
                Ok(()) => removed.push(path),
                Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
                Err(e) => {
                    return Err(e).with_context(|| format!("cannot remove '{}'", path.display()));
                }
            }
        }
        record::remove(&self.dir, names)?;
        for name in names {
            self.mine.remove(name);
        }
        Ok(removed)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const TEST: Command = Command::Validate;

    fn owner() -> Owner<'static> {
        Owner {
            command: TEST,
            option: "--out",
            replaces: &[],
            tolerates: &[Command::Sweep],
            tolerates_unrecorded: &nothing,
            writes: &[],
        }
    }

    fn write(dir: &Path, name: &str) {
        std::fs::write(dir.join(name), name).unwrap();
    }

    #[test]
    fn a_missing_directory_is_created_locked_and_empty() {
        let tmp = tempfile::tempdir().unwrap();
        let dir = tmp.path().join("a/b");
        let c = claim(&dir, &owner(), false).unwrap();
        assert!(dir.is_dir() && c.earlier().is_empty() && c.foreign().is_empty());
        assert!(dir.join(LOCK_FILE).is_file());
    }

    #[test]
    fn files_without_a_record_are_foreign_whatever_their_name_and_a_refusal_leaves_nothing() {
        let tmp = tempfile::tempdir().unwrap();
        write(tmp.path(), "surge_front.csv");
        let err = claim(tmp.path(), &owner(), false).unwrap_err().to_string();
        assert!(
            err.contains("'surge_front.csv'") && err.contains("--force"),
            "{err}"
        );
        assert!(err.contains("has no bench-sph-files.json"), "{err}");
        assert!(!tmp.path().join(LOCK_FILE).exists(), "nothing is created");
    }

    #[test]
    fn force_writes_beside_foreign_files_but_never_over_them() {
        let tmp = tempfile::tempdir().unwrap();
        write(tmp.path(), "a.csv");
        let mut c = claim(tmp.path(), &owner(), true).unwrap();
        assert!(c.check_writable("b.csv").is_ok());
        let err = c.check_writable("a.csv").unwrap_err().to_string();
        assert!(
            err.contains("was not written by bench-sph validate (no record"),
            "{err}"
        );
        c.remove_stale(&[]).unwrap();
        assert!(tmp.path().join("a.csv").exists(), "a foreign file stays");
    }

    #[test]
    fn recorded_files_are_own_tolerated_or_foreign_by_their_writer() {
        let tmp = tempfile::tempdir().unwrap();
        for name in ["mine.csv", "sweeps.csv", "traces.csv"] {
            write(tmp.path(), name);
        }
        record::add(tmp.path(), TEST, &["mine.csv"]).unwrap();
        record::add(tmp.path(), Command::Sweep, &["sweeps.csv"]).unwrap();
        record::add(tmp.path(), Command::Trace, &["traces.csv"]).unwrap();
        let err = claim(tmp.path(), &owner(), false).unwrap_err().to_string();
        assert!(
            err.contains("('traces.csv' of bench-sph trace)"),
            "only the trace's file is foreign: {err}"
        );
        let c = claim(tmp.path(), &owner(), true).unwrap();
        assert_eq!(c.earlier(), [("mine.csv".to_owned(), TEST)]);
        assert!(c.check_writable("mine.csv").is_ok());
        let err = c.check_writable("sweeps.csv").unwrap_err().to_string();
        assert!(
            err.contains("was not written by bench-sph validate"),
            "{err}"
        );
    }

    #[test]
    fn own_files_not_written_again_are_removed_and_forgotten() {
        let tmp = tempfile::tempdir().unwrap();
        for name in ["a.csv", "b.csv", ".a.csv.99.tmp"] {
            write(tmp.path(), name);
        }
        record::add(tmp.path(), TEST, &["a.csv", "b.csv", "never-written.csv"]).unwrap();
        let mut c = claim(tmp.path(), &owner(), false).unwrap();
        assert_eq!(c.earlier().len(), 2, "temporary files are not counted");
        let removed = c.remove_stale(&[tmp.path().join("a.csv")]).unwrap();
        assert_eq!(removed, [tmp.path().join("b.csv")]);
        assert!(tmp.path().join("a.csv").exists());
        let record = Record::read(tmp.path()).unwrap().unwrap();
        assert_eq!(record.files.keys().collect::<Vec<_>>(), ["a.csv"]);
    }

    #[test]
    fn a_directory_in_place_of_a_file_is_never_replaced_even_if_recorded() {
        let tmp = tempfile::tempdir().unwrap();
        std::fs::create_dir(tmp.path().join("chart.png")).unwrap();
        record::add(tmp.path(), TEST, &["chart.png"]).unwrap();
        let c = claim(tmp.path(), &owner(), true).unwrap();
        let err = c.check_writable("chart.png").unwrap_err().to_string();
        assert!(
            err.contains("a directory of that name is in the way"),
            "{err}"
        );
    }

    #[test]
    fn a_file_in_place_of_the_directory_is_an_error() {
        let tmp = tempfile::tempdir().unwrap();
        let file = tmp.path().join("f");
        std::fs::write(&file, "").unwrap();
        let err = claim(&file, &owner(), true).unwrap_err().to_string();
        assert!(err.contains("is not a directory"), "{err}");
    }
}
