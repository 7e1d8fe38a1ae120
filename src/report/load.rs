//! Reading a results directory: `meta.json` and `summary.csv` into the sweep's own types
//! ([`Meta`], [`SummaryRow`]), with errors that name the file and the line.

use std::path::{Path, PathBuf};

use anyhow::{Context, bail};

use crate::sweep::meta::Meta;
use crate::sweep::rows::SummaryRow;
use crate::sweep::{META_FILE, SUMMARY_FILE};

/// One sweep's results.
#[derive(Debug, Clone)]
pub struct Sweep {
    /// The results directory.
    pub dir: PathBuf,
    /// Its `meta.json`.
    pub meta: Meta,
    /// Its `summary.csv`, one row per cell, in file order (the sweep's plan order).
    pub rows: Vec<SummaryRow>,
}

/// Reads `dir/meta.json` and `dir/summary.csv`.
pub fn load(dir: &Path) -> anyhow::Result<Sweep> {
    if !dir.is_dir() {
        bail!("results directory '{}' does not exist", dir.display());
    }
    let meta = Meta::read(&dir.join(META_FILE))?;
    let rows = read_summary(&dir.join(SUMMARY_FILE))?;
    if rows.is_empty() {
        bail!(
            "'{}' has no cells: nothing to report",
            dir.join(SUMMARY_FILE).display()
        );
    }
    Ok(Sweep {
        dir: dir.to_path_buf(),
        meta,
        rows,
    })
}

/// Reads a `summary.csv`.
pub fn read_summary(path: &Path) -> anyhow::Result<Vec<SummaryRow>> {
    let mut reader = csv::Reader::from_path(path)
        .with_context(|| format!("cannot read '{}'", path.display()))?;
    let header = reader
        .headers()
        .with_context(|| format!("cannot read '{}'", path.display()))?
        .clone();
    let expected = crate::sweep::export::SUMMARY_COLUMNS;
    if header.iter().ne(expected.iter().copied()) {
        bail!(
            "'{}' is not a bench-sph summary.csv: its header is not {}",
            path.display(),
            expected.join(",")
        );
    }
    reader
        .deserialize::<SummaryRow>()
        .enumerate()
        .map(|(i, row)| {
            row.with_context(|| {
                format!(
                    "'{}' line {}: not a bench-sph summary row",
                    path.display(),
                    i + 2
                )
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_garbled_summary_names_the_file_and_line() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("summary.csv");
        let header = crate::sweep::export::SUMMARY_COLUMNS.join(",");
        std::fs::write(&path, format!("{header}\nseq,all-pairs,seed,x\n")).unwrap();
        let err = format!("{:#}", read_summary(&path).unwrap_err());
        assert!(err.contains("line 2"), "{err}");
        std::fs::write(&path, "a,b\n1,2\n").unwrap();
        let err = format!("{:#}", read_summary(&path).unwrap_err());
        assert!(err.contains("not a bench-sph summary.csv"), "{err}");
    }
}
