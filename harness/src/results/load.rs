//! Reading results directories leniently (`bench-sph report`): `meta.json`, `summary.csv` and
//! `trials.csv` into the schema's types ([`Meta`], [`SummaryRow`], [`TrialRow`]), with errors
//! that name the file and the line, and every cell checked before it can become a number in
//! the report.
//!
//! - Files of this version and of the first release (before the contention and interval
//!   columns) are read; the missing columns are empty.
//! - A line that is not a row (cut off by a kill mid-write, or garbled) is left out and
//!   listed, like a `--resume` would drop it; a file whose header is not a results file's
//!   is an error.
//! - A cell whose numbers are impossible (not finite and positive, statistics that are not
//!   those of its trial rows, counts beyond the documented limits) is dropped, and the report
//!   lists it with the reason ([`Sweep::dropped`]).
//! - The same directory twice is refused ([`load_each`]), and so is the same cell in two
//!   directories of one study ([`refuse_shared_cells`]): counting a cell twice would weigh it
//!   double in every finding. The report checks cells per machine: the same cell measured on
//!   two machines is what a comparison of machines is made of.

use std::collections::{HashMap, HashSet};
use std::path::{Path, PathBuf};

use anyhow::{Context, bail};

use super::anchor::{ANCHOR_COLUMNS, AnchorRun};
use super::files::{ANCHOR_FILE, META_FILE, PASS_COST_FILE, SUMMARY_FILE, TRIALS_FILE};
use super::key::Cell;
use super::meta::Meta;
use super::rows::{
    Phase, SUMMARY_COLUMNS, SummaryRow, TRIAL_COLUMNS, TrialRow, is_older_summary_header,
    is_older_trial_header,
};
use super::validate;
use crate::io::capped;
use crate::run::pass_cost::{CostRow, PASS_COST_COLUMNS};

/// One sweep's results.
#[derive(Debug, Clone)]
pub struct Sweep {
    /// The results directory.
    pub dir: PathBuf,
    /// Its `meta.json`.
    pub meta: Meta,
    /// Its `summary.csv` cells of the grid phase that passed the checks, in file order (the
    /// plan's order): every cell measured.
    pub rows: Vec<SummaryRow>,
    /// Its cells of the confirmation phase that passed the checks: the chosen cells measured
    /// again ([`crate::results::rows::Phase::Confirm`]); empty when the sweep had none.
    pub confirmed: Vec<SummaryRow>,
    /// The trial rows of the cells kept (both phases), cell by cell; empty without a
    /// `trials.csv`.
    pub trials: Vec<TrialRow>,
    /// Cells left out, each with why.
    pub dropped: Vec<String>,
    /// Whether the directory has no `trials.csv`: its summary statistics could not be checked
    /// against its runs (only [`validate::summary_alone`]), so the report takes them on trust
    /// and says so.
    pub without_trials: bool,
    /// Its `pass-cost.csv` (`sweep --pass-cost`): what a pass costs each strategy at each core
    /// count; empty without one.
    pub pass_costs: Vec<CostRow>,
    /// Its `anchor.csv` (`sweep --anchor`): the OpenMP anchor's runs; empty without one.
    pub anchor: Vec<AnchorRun>,
}

/// Reads every directory of `dirs`, refusing a directory given twice (under any path).
pub fn load_each(dirs: &[PathBuf]) -> anyhow::Result<Vec<Sweep>> {
    let mut seen: HashMap<PathBuf, &Path> = HashMap::new();
    for d in dirs {
        let canonical = d
            .canonicalize()
            .with_context(|| format!("results directory '{}' does not exist", d.display()))?;
        if let Some(first) = seen.insert(canonical, d) {
            bail!(
                "results directory '{}' is given twice (also as '{}'): each cell would count \
                 twice",
                d.display(),
                first.display()
            );
        }
    }
    dirs.iter().map(|d| load(d)).collect()
}

/// Refuses `sweeps` that hold the same cell twice: they are to be pooled into one study (one
/// machine's), where a cell must count once.
pub fn refuse_shared_cells<'a>(sweeps: impl IntoIterator<Item = &'a Sweep>) -> anyhow::Result<()> {
    let mut owner: HashMap<Cell, &Path> = HashMap::new();
    for s in sweeps {
        for r in &s.rows {
            if let Some(first) = owner.insert(r.key(), &s.dir) {
                bail!(
                    "the cell {} is in both '{}' and '{}': report them separately, or remove \
                     it from one (a cell must count once)",
                    r.key().label_with_group(),
                    first.display(),
                    s.dir.display()
                );
            }
        }
    }
    Ok(())
}

/// Reads `dir/meta.json`, `dir/summary.csv` and (where present) `dir/trials.csv`.
pub fn load(dir: &Path) -> anyhow::Result<Sweep> {
    if !dir.is_dir() {
        bail!("results directory '{}' does not exist", dir.display());
    }
    let meta = Meta::read(&dir.join(META_FILE))?;
    let mut dropped = Vec::new();
    let (summary, bad) = read_summary(&dir.join(SUMMARY_FILE))?;
    dropped.extend(bad);
    if summary.is_empty() {
        bail!(
            "'{}' has no cells: nothing to report",
            dir.join(SUMMARY_FILE).display()
        );
    }
    let trials = match read_csv_if_exists(
        &dir.join(TRIALS_FILE),
        capped::TRIALS_CSV,
        &TRIAL_COLUMNS,
        is_older_trial_header,
        "trial",
    )? {
        Some((rows, bad)) => {
            dropped.extend(bad);
            Some(rows)
        }
        None => None,
    };
    let without_trials = trials.is_none();
    let believed = believed(summary, trials);
    dropped.extend(believed.dropped.iter().map(ToString::to_string));
    let (confirmed, rows): (Vec<SummaryRow>, Vec<SummaryRow>) = believed
        .rows
        .into_iter()
        .partition(|r| r.phase == crate::results::rows::Phase::Confirm);
    if rows.is_empty() {
        bail!(
            "'{}' has no usable cells ({} dropped; the first: {})",
            dir.display(),
            dropped.len(),
            dropped.first().map_or("", String::as_str)
        );
    }
    // Read only where the sweep measured them: a file of that name is otherwise not its.
    let (pass_costs, bad) = read_beside(
        meta.params.pass_cost,
        &dir.join(PASS_COST_FILE),
        &PASS_COST_COLUMNS,
        "pass cost",
        CostRow::problem,
    )?;
    dropped.extend(bad);
    let (anchor, bad) = read_beside(
        meta.params.anchor.is_some(),
        &dir.join(ANCHOR_FILE),
        &ANCHOR_COLUMNS,
        "anchor",
        AnchorRun::problem,
    )?;
    dropped.extend(bad);
    Ok(Sweep {
        pass_costs,
        anchor,
        dir: dir.to_path_buf(),
        meta,
        rows,
        confirmed,
        trials: believed.trials,
        dropped,
        without_trials,
    })
}

/// The cells of a results directory that can be believed, with their trial rows.
#[derive(Debug, Clone, Default)]
pub struct Believed {
    /// Summary rows that passed the checks, in file order.
    pub rows: Vec<SummaryRow>,
    /// Their trial rows, cell by cell, in trial order (empty without a `trials.csv`).
    pub trials: Vec<TrialRow>,
    /// Each row left out, with why.
    pub dropped: Vec<Dropped>,
    /// Cells with trial rows but no summary row, with how many (an unfinished cell's runs, or
    /// a summary row deleted): not an error in a sweep, which may be unfinished.
    pub without_summary: Vec<Dropped>,
}

/// A summary row left out ([`believed`]): its cell, and why.
#[derive(Debug, Clone, PartialEq)]
pub struct Dropped {
    /// The row's cell.
    pub cell: Cell,
    /// The row's phase.
    pub phase: Phase,
    /// Why it cannot be believed.
    pub why: String,
}

impl std::fmt::Display for Dropped {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}: {}", self.cell.label_with_group(), self.why)
    }
}

/// A caller's own check of a cell that passed [`believed`]'s (its summary row and its trial
/// rows, in trial order).
pub type CheckCell<'a> = &'a dyn Fn(&SummaryRow, &[TrialRow]) -> Result<(), String>;

/// The cells of `summary` that pass the checks: a cell's first row only, and its statistics
/// those of its rows in `trials` ([`validate::cell`]) or, without a `trials.csv` (`None`),
/// possible on their own ([`validate::summary_alone`]).
pub fn believed(summary: Vec<SummaryRow>, trials: Option<Vec<TrialRow>>) -> Believed {
    believed_with(summary, trials, &|_, _| Ok(()))
}

/// [`believed`], each cell also passing `check` (`bench-sph merge`: the cell's numbers of
/// trials and rounds are its plan's).
pub fn believed_with(
    summary: Vec<SummaryRow>,
    trials: Option<Vec<TrialRow>>,
    check: CheckCell<'_>,
) -> Believed {
    let have_trials = trials.is_some();
    let mut by_cell: HashMap<(Cell, Phase), Vec<TrialRow>> = HashMap::new();
    for t in trials.into_iter().flatten() {
        by_cell.entry(t.phased_key()).or_default().push(t);
    }
    let mut seen = HashSet::new();
    let mut out = Believed::default();
    for row in summary {
        let mut of_cell = Vec::new();
        let checked = if !seen.insert(row.phased_key()) {
            Err("a second summary row of the same cell".to_owned())
        } else if have_trials {
            of_cell = by_cell.remove(&row.phased_key()).unwrap_or_default();
            of_cell.sort_by_key(|t| t.trial);
            validate::cell(&row, &of_cell)
        } else {
            validate::summary_alone(&row)
        };
        match checked.and_then(|()| check(&row, &of_cell)) {
            Ok(()) => {
                out.trials.extend(of_cell);
                out.rows.push(row);
            }
            Err(why) => out.dropped.push(Dropped {
                cell: row.key(),
                phase: row.phase,
                why,
            }),
        }
    }
    let mut rest: Vec<((Cell, Phase), Vec<TrialRow>)> = by_cell.into_iter().collect();
    rest.sort_by_key(|((cell, phase), _)| (cell.label_with_group(), *phase));
    out.without_summary = rest
        .into_iter()
        .map(|((cell, phase), trials)| Dropped {
            cell,
            phase,
            why: format!(
                "summary.csv has no row of it, though trials.csv holds {} of its {} phase \
                 (the row was deleted or edited, or the cell never finished)",
                crate::output::console::plural(trials.len(), "trial row", "trial rows"),
                phase.as_str()
            ),
        })
        .collect();
    out
}

/// Reads a `summary.csv` (this version's columns or the first release's): its rows, and a
/// note for each line that is not one.
pub fn read_summary(path: &Path) -> anyhow::Result<(Vec<SummaryRow>, Vec<String>)> {
    read_csv(
        path,
        capped::SUMMARY_CSV,
        &SUMMARY_COLUMNS,
        is_older_summary_header,
        "summary",
    )
}

/// Reads a `trials.csv` (this version's columns or the first release's), as
/// [`read_summary`].
pub fn read_trials(path: &Path) -> anyhow::Result<(Vec<TrialRow>, Vec<String>)> {
    read_csv(
        path,
        capped::TRIALS_CSV,
        &TRIAL_COLUMNS,
        is_older_trial_header,
        "trial",
    )
}

/// The rows of a file a sweep writes beside its cells (`pass-cost.csv`, `anchor.csv`) where
/// the sweep `asked` for it, and a note naming each line that is not a row or whose numbers
/// are impossible (`problem`); none without the file or the asking.
fn read_beside<R: serde::de::DeserializeOwned>(
    asked: bool,
    path: &Path,
    columns: &[&str],
    what: &str,
    problem: impl Fn(&R) -> Option<String>,
) -> anyhow::Result<(Vec<R>, Vec<String>)> {
    if !asked {
        return Ok(Default::default());
    }
    let (rows, mut bad): (Vec<R>, Vec<String>) =
        read_csv_if_exists(path, capped::SUMMARY_CSV, columns, |_| false, what)?
            .unwrap_or_default();
    let mut kept = Vec::with_capacity(rows.len());
    for (i, row) in rows.into_iter().enumerate() {
        match problem(&row) {
            // The header is line 1; a row that did not parse is already noted, so the number
            // is the row's place among those that did.
            Some(why) => bad.push(format!(
                "'{}' {what} row {}: left out ({why})",
                path.display(),
                i + 1
            )),
            None => kept.push(row),
        }
    }
    Ok((kept, bad))
}

/// The rows and notes of [`read_csv`]; a missing file is an error.
fn read_csv<R: serde::de::DeserializeOwned>(
    path: &Path,
    kind: capped::Kind,
    columns: &[&str],
    older: fn(&[&str]) -> bool,
    what: &str,
) -> anyhow::Result<(Vec<R>, Vec<String>)> {
    read_csv_if_exists(path, kind, columns, older, what)?
        .with_context(|| format!("cannot read '{}': no such file", path.display()))
}

/// The rows of a results CSV (read as a `kind`: a regular file within its cap, see
/// [`capped`]) whose header is `columns` or one that `older` accepts (an earlier version's
/// file), and a note naming each line that is not a row; `None` when there is no such file.
fn read_csv_if_exists<R: serde::de::DeserializeOwned>(
    path: &Path,
    kind: capped::Kind,
    columns: &[&str],
    older: fn(&[&str]) -> bool,
    what: &str,
) -> anyhow::Result<Option<(Vec<R>, Vec<String>)>> {
    let Some(file) = capped::open_if_exists(path, kind)? else {
        return Ok(None);
    };
    let mut reader = csv::Reader::from_reader(file);
    let header = reader.headers().map_err(|e| csv_error(e, path))?.clone();
    let found: Vec<&str> = header.iter().collect();
    if found != columns && !older(&found) {
        bail!(
            "'{}' is not a bench-sph {}: its header is not {}",
            path.display(),
            path.file_name().unwrap_or_default().to_string_lossy(),
            columns.join(",")
        );
    }
    let mut rows = Vec::new();
    let mut bad = Vec::new();
    for (i, row) in reader.deserialize::<R>().enumerate() {
        match row {
            Ok(row) => rows.push(row),
            // Reading stopped (the cap, a failing disk): not a row to leave out.
            Err(e) if e.is_io_error() => return Err(csv_error(e, path)),
            Err(e) => bad.push(format!(
                "'{}' line {}: not a bench-sph {what} row ({})",
                path.display(),
                i + 2,
                validate::unreadable(&e, columns)
            )),
        }
    }
    Ok(Some((rows, bad)))
}

/// A CSV error of reading `path`: the cap's refusal where that is what stopped it.
fn csv_error(err: csv::Error, path: &Path) -> anyhow::Error {
    let context = || format!("cannot read '{}'", path.display());
    if !err.is_io_error() {
        return anyhow::Error::new(err).context(context());
    }
    match err.into_kind() {
        csv::ErrorKind::Io(e) => capped::io_error(e, path),
        other => anyhow::anyhow!("{other:?}").context(context()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_garbled_row_is_left_out_naming_the_file_and_line_and_a_foreign_header_is_an_error() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("summary.csv");
        let header = SUMMARY_COLUMNS.join(",");
        std::fs::write(&path, format!("{header}\nseq,all-pairs,seed,x\n")).unwrap();
        let (rows, bad) = read_summary(&path).unwrap();
        assert!(rows.is_empty());
        assert!(bad[0].contains("line 2"), "{bad:?}");
        std::fs::write(&path, "a,b\n1,2\n").unwrap();
        let err = format!("{:#}", read_summary(&path).unwrap_err());
        assert!(err.contains("not a bench-sph summary.csv"), "{err}");
    }

    #[test]
    fn a_first_release_summary_reads_with_empty_new_columns() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("summary.csv");
        let header = SUMMARY_COLUMNS[..crate::results::rows::LEGACY_SUMMARY_COLUMNS].join(",");
        std::fs::write(
            &path,
            format!("{header}\nseq,all-pairs,seed,60,3,1,,,2,1.5,0.5,1.0,1.5,2.0,1.5,1.0,1.0,0,false,00000000000000aa,ok,\n"),
        )
        .unwrap();
        let (rows, _) = read_summary(&path).unwrap();
        assert_eq!(rows.len(), 1);
        assert_eq!((rows[0].mean_ci_low_s, rows[0].contended), (None, None));
    }

    #[test]
    fn a_row_naming_an_unknown_strategy_is_left_out_as_unreadable() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("summary.csv");
        let header = SUMMARY_COLUMNS[..crate::results::rows::LEGACY_SUMMARY_COLUMNS].join(",");
        let row = "all-pairs,seed,60,3,1,,,2,1.5,0.5,1.0,1.5,2.0,1.5,1.0,1.0,0,false,00000000000000aa,ok,";
        std::fs::write(&path, format!("{header}\nseq,{row}\nturbo,{row}\n")).unwrap();
        let (rows, bad) = read_summary(&path).unwrap();
        assert_eq!(rows.len(), 1);
        assert_eq!(rows[0].strategy, sph_strategies::StrategyName::Seq);
        assert_eq!(bad.len(), 1);
        assert!(
            bad[0].contains("line 3: not a bench-sph summary row"),
            "{bad:?}"
        );
    }

    #[test]
    fn a_pass_cost_row_with_impossible_numbers_is_left_out_naming_why() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join(PASS_COST_FILE);
        let header = PASS_COST_COLUMNS.join(",");
        std::fs::write(
            &path,
            format!(
                "{header}\nteam,2,5.0,6.5,6.4,6.6,1.5,false\nteam,2,5.0,NaN,6.4,6.6,NaN,false\n\
                 team,0,5.0,6.5,6.4,6.6,1.5,false\nteam,2,5.0,6.5,6.6,6.7,1.5,false\n"
            ),
        )
        .unwrap();
        let (rows, bad): (Vec<CostRow>, _) = read_beside(
            true,
            &path,
            &PASS_COST_COLUMNS,
            "pass cost",
            CostRow::problem,
        )
        .unwrap();
        assert_eq!(rows.len(), 1);
        assert_eq!(bad.len(), 3, "{bad:?}");
        assert!(
            bad[0].contains("row 2: left out (a time that is not finite"),
            "{bad:?}"
        );
        assert!(bad[1].contains("row 3: left out (0 cores)"), "{bad:?}");
        assert!(bad[2].contains("does not hold its time"), "{bad:?}");
        let none: (Vec<CostRow>, _) = read_beside(
            true,
            &dir.path().join("missing.csv"),
            &PASS_COST_COLUMNS,
            "pass cost",
            CostRow::problem,
        )
        .unwrap();
        assert!(none.0.is_empty() && none.1.is_empty());
    }
}
