//! Which files in an output directory a command may replace.
//!
//! Every command that writes a directory (`sweep --out`, `trace --out`, `render --frames`,
//! `report --out`) claims it first with [`claim`]:
//! - a missing directory is created; an empty one is used;
//! - a directory holding only the command's **own** earlier output (as the command
//!   recognises it: [`Owner::owns`]) is reused, and after writing, [`Claimed::remove_stale`]
//!   deletes the earlier files this run did not write again (old frames, old charts);
//! - a directory holding anything else is refused, naming what it holds, unless `--force`;
//!   with `--force` the foreign entries stay untouched, and writing a file whose name belongs
//!   to a foreign file is still an error ([`Claimed::check_writable`]): `--force` replaces
//!   only the command's own files.
//!
//! Entries that [`Owner::tolerates`] (the report's input sweeps in its own directory, say)
//! are neither replaced nor refused. Temporary files of [`super::atomic`] are ignored.

use std::path::{Path, PathBuf};

use anyhow::{Context, bail};

use super::atomic::is_temporary;

/// How a command recognises its own output.
pub struct Owner<'a> {
    /// The command, as the user typed it, e.g. `bench-sph trace`.
    pub command: &'a str,
    /// The option that names the directory, e.g. `--out`.
    pub option: &'a str,
    /// Whether a top-level entry of the directory is this command's earlier output.
    pub owns: &'a dyn Fn(&Path) -> bool,
    /// Whether an entry that is not the command's own may stay beside its output.
    pub tolerates: &'a dyn Fn(&Path) -> bool,
}

/// Tolerates nothing: for [`Owner::tolerates`].
pub fn nothing(_: &Path) -> bool {
    false
}

/// A directory a command may write into.
#[derive(Debug, Clone, PartialEq)]
pub struct Claimed {
    dir: PathBuf,
    command: String,
    earlier: Vec<PathBuf>,
    foreign: Vec<PathBuf>,
}

/// Claims `dir` for `owner`; see the module docs.
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
    let mut earlier = Vec::new();
    let mut foreign = Vec::new();
    for path in entries(dir)? {
        if (owner.owns)(&path) {
            earlier.push(path);
        } else if !(owner.tolerates)(&path) {
            foreign.push(path);
        }
    }
    if !foreign.is_empty() && !force {
        bail!(
            "{} '{}' holds files that {} did not write ({}); choose a new or empty directory, \
             or pass --force to write beside them (only {}'s own files are replaced)",
            owner.option,
            dir.display(),
            owner.command,
            list(&foreign),
            owner.command
        );
    }
    Ok(Claimed {
        dir: dir.to_path_buf(),
        command: owner.command.to_owned(),
        earlier,
        foreign,
    })
}

/// The entries of `dir`, sorted, without temporary files.
fn entries(dir: &Path) -> anyhow::Result<Vec<PathBuf>> {
    let read = std::fs::read_dir(dir)
        .with_context(|| format!("cannot read directory '{}'", dir.display()))?;
    let mut out = Vec::new();
    for entry in read {
        let entry = entry.with_context(|| format!("cannot read directory '{}'", dir.display()))?;
        if !is_temporary(&entry.file_name().to_string_lossy()) {
            out.push(entry.path());
        }
    }
    out.sort();
    Ok(out)
}

/// Up to three names, then how many more.
fn list(paths: &[PathBuf]) -> String {
    let mut names: Vec<String> = paths
        .iter()
        .take(3)
        .map(|p| {
            let name = p.file_name().unwrap_or_default().to_string_lossy();
            if p.is_dir() {
                format!("'{name}/'")
            } else {
                format!("'{name}'")
            }
        })
        .collect();
    if paths.len() > 3 {
        names.push(format!("and {} more", paths.len() - 3));
    }
    names.join(", ")
}

impl Claimed {
    /// The directory.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// The command's own files that were there before this run.
    pub fn earlier(&self) -> &[PathBuf] {
        &self.earlier
    }

    /// Entries that were not the command's own (non-empty only with `--force`).
    pub fn foreign(&self) -> &[PathBuf] {
        &self.foreign
    }

    /// Whether the directory held nothing but tolerated entries.
    pub fn was_empty(&self) -> bool {
        self.earlier.is_empty() && self.foreign.is_empty()
    }

    /// `dir/name`, unless that names a file the command did not write.
    pub fn check_writable(&self, name: &str) -> anyhow::Result<PathBuf> {
        let path = self.dir.join(name);
        if self.foreign.contains(&path) {
            bail!(
                "cannot write '{}': it exists and was not written by {} (--force replaces \
                 only that command's own files)",
                path.display(),
                self.command
            );
        }
        Ok(path)
    }

    /// Removes the command's earlier files that this run did not write (`written`), and
    /// returns them.
    pub fn remove_stale(&self, written: &[PathBuf]) -> anyhow::Result<Vec<PathBuf>> {
        let mut removed = Vec::new();
        for path in self.earlier.iter().filter(|p| !written.contains(p)) {
            let result = if path.is_dir() {
                std::fs::remove_dir_all(path)
            } else {
                std::fs::remove_file(path)
            };
            match result {
                Ok(()) => removed.push(path.clone()),
                Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
                Err(e) => {
                    return Err(e).with_context(|| {
                        format!("cannot remove the stale file '{}'", path.display())
                    });
                }
            }
        }
        Ok(removed)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn csv_is_mine(p: &Path) -> bool {
        p.extension().is_some_and(|e| e == "csv")
    }

    fn owner<'a>(owns: &'a dyn Fn(&Path) -> bool) -> Owner<'a> {
        Owner {
            command: "bench-sph test",
            option: "--out",
            owns,
            tolerates: &nothing,
        }
    }

    #[test]
    fn a_missing_directory_is_created_and_an_empty_one_used() {
        let tmp = tempfile::tempdir().unwrap();
        let dir = tmp.path().join("a/b");
        let c = claim(&dir, &owner(&csv_is_mine), false).unwrap();
        assert!(dir.is_dir() && c.was_empty());
    }

    #[test]
    fn a_directory_with_foreign_files_is_refused_naming_them() {
        let tmp = tempfile::tempdir().unwrap();
        std::fs::write(tmp.path().join("meta.json"), "{}").unwrap();
        std::fs::write(tmp.path().join("x.csv"), "").unwrap();
        let err = claim(tmp.path(), &owner(&csv_is_mine), false).unwrap_err();
        let msg = err.to_string();
        assert!(
            msg.contains("'meta.json'") && !msg.contains("x.csv"),
            "{msg}"
        );
        assert!(msg.contains("--force"), "{msg}");
    }

    #[test]
    fn force_writes_beside_foreign_files_but_never_over_them() {
        let tmp = tempfile::tempdir().unwrap();
        std::fs::write(tmp.path().join("meta.json"), "{}").unwrap();
        let c = claim(tmp.path(), &owner(&csv_is_mine), true).unwrap();
        assert!(c.check_writable("stats.csv").is_ok());
        let err = c.check_writable("meta.json").unwrap_err().to_string();
        assert!(err.contains("was not written by bench-sph test"), "{err}");
        c.remove_stale(&[]).unwrap();
        assert!(
            tmp.path().join("meta.json").exists(),
            "a foreign file is never removed"
        );
    }

    #[test]
    fn own_files_not_written_again_are_removed_as_stale() {
        let tmp = tempfile::tempdir().unwrap();
        for name in ["a.csv", "b.csv"] {
            std::fs::write(tmp.path().join(name), "").unwrap();
        }
        std::fs::write(tmp.path().join(".a.csv.99.tmp"), "").unwrap();
        let c = claim(tmp.path(), &owner(&csv_is_mine), false).unwrap();
        assert_eq!(c.earlier().len(), 2, "temporary files are not counted");
        let removed = c.remove_stale(&[tmp.path().join("a.csv")]).unwrap();
        assert_eq!(removed, [tmp.path().join("b.csv")]);
        assert!(tmp.path().join("a.csv").exists());
    }

    #[test]
    fn a_file_in_place_of_the_directory_is_an_error() {
        let tmp = tempfile::tempdir().unwrap();
        let file = tmp.path().join("f");
        std::fs::write(&file, "").unwrap();
        let err = claim(&file, &owner(&csv_is_mine), true)
            .unwrap_err()
            .to_string();
        assert!(err.contains("is not a directory"), "{err}");
    }
}
