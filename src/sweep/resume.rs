//! `--resume DIR`: what an earlier session finished, and the repairs that make each trial
//! appear exactly once.
//!
//! A cell counts as finished when `summary.csv` has its row and `trials.csv` has exactly
//! `trials` rows for it (numbered 1, 2, …). Everything else of an unfinished cell — trial rows
//! written just before a kill, a line cut off mid-write — is dropped, both files are written
//! back without it, and the cell runs again. Failed cells are finished too: their failure is a
//! result (delete their rows by hand to retry them).
//!
//! A finished cell is believed only if it passes [`crate::results::validate::cell`] (finite
//! positive
//! times, statistics that are those of its trials) and the caller's own check (`--resume`:
//! the cell is in the plan and has the sweep's number of trials); otherwise it is dropped,
//! listed in [`Repaired::rejected`], and runs again.

use std::collections::{HashMap, HashSet};
use std::path::Path;

use anyhow::Context;

use super::export::to_csv;
use super::plan::Cell;
use crate::results::rows::{
    EARLIER_SUMMARY_WIDTHS, EARLIER_TRIAL_WIDTHS, SUMMARY_COLUMNS, SummaryRow, TRIAL_COLUMNS,
    TrialRow,
};

/// A results file whose header is not this version's.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error(
    "{file} has the columns '{found}', not those bench-sph {} writes",
    crate::results::meta::VERSION
)]
pub struct UnexpectedColumns {
    /// The file's name.
    pub file: &'static str,
    /// Its header line.
    pub found: String,
}

/// The finished cells of a results directory, and its files with everything else removed.
#[derive(Debug, Clone, PartialEq)]
pub struct Repaired {
    /// The summary rows of the finished cells, in file order.
    pub finished: Vec<SummaryRow>,
    /// The trial rows of the finished cells.
    pub finished_trials: Vec<TrialRow>,
    /// Finished-looking cells that were dropped: the cell and why.
    pub rejected: Vec<String>,
    /// `trials.csv` as it should be: header plus the finished cells' trial rows.
    pub trials_csv: Vec<u8>,
    /// `summary.csv` as it should be: header plus the finished cells' rows.
    pub summary_csv: Vec<u8>,
    /// Trial rows kept.
    pub kept_trial_rows: usize,
    /// Trial rows (or broken lines) dropped from `trials.csv`.
    pub dropped_trial_rows: usize,
    /// Summary rows (or broken lines) dropped from `summary.csv`.
    pub dropped_summary_rows: usize,
    /// Whether a file had the columns of an earlier version (`reference_shard`, `pin` or `smt`
    /// of `summary.csv`, `pin` or `passes_alone` of `trials.csv` missing): its repaired contents
    /// have every column, those empty (the upgrade).
    pub upgraded: bool,
}

/// Repairs the contents of `trials.csv` and `summary.csv` (either may be empty: no file);
/// `check` is the caller's own test of a finished cell (see the module docs).
// Over ~60 lines on purpose: the repair is one pass over the rows whose steps (first row per cell,
// trials once per number, finished = complete and believed) are the module docs' list in order.
pub fn repair(
    trials: &[u8],
    summary: &[u8],
    check: &dyn Fn(&SummaryRow) -> Result<(), String>,
) -> Result<Repaired, UnexpectedColumns> {
    let (summary_rows, mut dropped_summary_rows, older_summary) = read_rows::<SummaryRow>(
        summary,
        "summary.csv",
        &SUMMARY_COLUMNS,
        &EARLIER_SUMMARY_WIDTHS,
    )?;
    let (trial_rows, mut dropped_trial_rows, older_trials) =
        read_rows::<TrialRow>(trials, "trials.csv", &TRIAL_COLUMNS, &EARLIER_TRIAL_WIDTHS)?;

    // The first summary row of each cell; the trial rows of each cell, once per number.
    let mut seen = HashSet::new();
    let mut candidates = Vec::new();
    for row in summary_rows {
        if seen.insert(row.key()) {
            candidates.push(row);
        } else {
            dropped_summary_rows += 1;
        }
    }
    let mut by_cell: HashMap<Cell, Vec<TrialRow>> = HashMap::new();
    for row in trial_rows {
        let rows = by_cell.entry(row.key()).or_default();
        if rows.iter().any(|r| r.trial == row.trial) {
            dropped_trial_rows += 1;
        } else {
            rows.push(row);
        }
    }

    // Finished = a summary row and trials numbered exactly 1..=trials.
    let mut finished = Vec::new();
    let mut kept = Vec::new();
    let mut rejected = Vec::new();
    for row in candidates {
        let mut trials = by_cell.remove(&row.key()).unwrap_or_default();
        trials.sort_by_key(|t| t.trial);
        let complete =
            trials.len() == row.trials && trials.iter().enumerate().all(|(i, t)| t.trial == i + 1);
        let believed = if complete {
            crate::results::validate::cell(&row, &trials).and_then(|()| check(&row))
        } else {
            Ok(())
        };
        if let Err(why) = &believed {
            rejected.push(format!("{}: {why}", row.key().label_with_group()));
        }
        if complete && believed.is_ok() {
            kept.extend(trials);
            finished.push(row);
        } else {
            dropped_trial_rows += trials.len();
            dropped_summary_rows += 1;
        }
    }
    dropped_trial_rows += by_cell.values().map(Vec::len).sum::<usize>();

    let csv_bytes = |result: csv::Result<Vec<u8>>| result.expect("CSV into memory cannot fail");
    Ok(Repaired {
        trials_csv: csv_bytes(to_csv(&TRIAL_COLUMNS, &kept)),
        summary_csv: csv_bytes(to_csv(&SUMMARY_COLUMNS, &finished)),
        kept_trial_rows: kept.len(),
        finished,
        finished_trials: kept,
        rejected,
        dropped_trial_rows,
        dropped_summary_rows,
        upgraded: older_summary || older_trials,
    })
}

/// The complete rows of a CSV file, the number of lines that were not (a last line without
/// its newline, cut off by a kill, or a row that does not parse), and whether its header was
/// the first `w` of `columns` for a width `w` of `older` (an earlier version's file, whose
/// missing columns are empty).
fn read_rows<R: serde::de::DeserializeOwned>(
    bytes: &[u8],
    file: &'static str,
    columns: &[&str],
    older: &[usize],
) -> Result<(Vec<R>, usize, bool), UnexpectedColumns> {
    let complete = match bytes.iter().rposition(|&b| b == b'\n') {
        Some(last) => &bytes[..=last],
        None => &[][..],
    };
    let mut dropped = usize::from(complete.len() < bytes.len());
    if complete.is_empty() {
        return Ok((Vec::new(), dropped, false));
    }
    let mut reader = csv::ReaderBuilder::new()
        .has_headers(true)
        .flexible(true)
        .from_reader(complete);
    let header = reader
        .headers()
        .map(|h| h.iter().collect::<Vec<_>>().join(","));
    let is_older = |h: &str| older.iter().any(|&w| h == columns[..w].join(","));
    let upgraded = match header {
        Ok(h) if h == columns.join(",") => false,
        Ok(h) if is_older(&h) => true,
        Ok(h) => return Err(UnexpectedColumns { file, found: h }),
        Err(_) => {
            return Err(UnexpectedColumns {
                file,
                found: String::from_utf8_lossy(
                    complete.split(|&b| b == b'\n').next().unwrap_or_default(),
                )
                .into_owned(),
            });
        }
    };
    let mut rows = Vec::new();
    for record in reader.deserialize::<R>() {
        match record {
            Ok(row) => rows.push(row),
            Err(_) => dropped += 1,
        }
    }
    Ok((rows, dropped, upgraded))
}

/// Reads `dir`'s CSV files (a missing one counts as empty), repairs them with `check`, and
/// writes the repaired contents back (each through a temporary file renamed over the
/// original).
pub fn load_and_repair(
    dir: &Path,
    check: &dyn Fn(&SummaryRow) -> Result<(), String>,
) -> anyhow::Result<Repaired> {
    let read = |name: &str| -> anyhow::Result<Vec<u8>> {
        let path = dir.join(name);
        match std::fs::read(&path) {
            Ok(bytes) => Ok(bytes),
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(Vec::new()),
            Err(e) => Err(e).with_context(|| format!("cannot read '{}'", path.display())),
        }
    };
    let repaired = repair(&read("trials.csv")?, &read("summary.csv")?, check)
        .with_context(|| format!("cannot resume '{}'", dir.display()))?;
    for (name, bytes) in [
        ("trials.csv", &repaired.trials_csv),
        ("summary.csv", &repaired.summary_csv),
    ] {
        crate::output::atomic::write(&dir.join(name), bytes)?;
    }
    Ok(repaired)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::clock::Elapsed;
    use crate::results::key::test_group;
    use crate::sph::neighbors::NeighborMode;
    use crate::sweep::export::Exporter;
    use crate::sweep::plan::Cell;
    use crate::sweep::rows::{Measured, summary_row, test_context, trial_rows};
    use sph_strategies::StrategyName;

    fn cell(cores: usize) -> Cell {
        Cell {
            group: test_group(NeighborMode::AllPairs),
            strategy: StrategyName::RayonIter,
            cores,
            chunks: None,
            pin: crate::topology::Pin::None,
        }
    }

    fn measured(k: usize) -> Vec<Measured> {
        (1..=k)
            .map(|i| Measured {
                elapsed: Elapsed {
                    wall_s: i as f64,
                    cpu_s: i as f64,
                    foreign: None,
                },
                load1: None,
                checksum: "00000000000000ff".to_owned(),
            })
            .collect()
    }

    /// Two finished cells, as an uninterrupted session writes them.
    fn two_cells() -> (Vec<u8>, Vec<u8>) {
        let (mut t, mut s) = (Vec::new(), Vec::new());
        let mut e = Exporter::new(&mut t, &mut s, true).unwrap();
        for cores in [1, 2] {
            let m = measured(3);
            e.write_cell(
                &trial_rows(&cell(cores), &m, None),
                &summary_row(&cell(cores), &m, None, &test_context(Some(&[1.0]), 2)),
            )
            .unwrap();
        }
        drop(e);
        (t, s)
    }

    #[test]
    fn intact_files_come_back_unchanged() {
        let (t, s) = two_cells();
        let r = repair(&t, &s, &|_| Ok(())).unwrap();
        assert_eq!(r.finished.len(), 2);
        assert_eq!(
            (
                r.kept_trial_rows,
                r.dropped_trial_rows,
                r.dropped_summary_rows
            ),
            (6, 0, 0)
        );
        assert_eq!(r.trials_csv, t);
        assert_eq!(r.summary_csv, s);
    }

    #[test]
    fn trial_rows_of_a_cell_without_a_summary_row_are_dropped() {
        let (mut t, s) = two_cells();
        let mut e = Exporter::new(&mut t, Vec::new(), false).unwrap();
        e.write_cell(
            &trial_rows(&cell(3), &measured(2), None),
            &summary_row(&cell(3), &measured(2), None, &test_context(None, 2)),
        )
        .unwrap();
        drop(e);
        let r = repair(&t, &s, &|_| Ok(())).unwrap();
        assert_eq!(r.finished.len(), 2);
        assert_eq!(r.dropped_trial_rows, 2);
        assert_eq!(r.trials_csv, two_cells().0);
    }

    #[test]
    fn a_line_cut_off_mid_write_is_dropped() {
        let (t, mut s) = two_cells();
        let mut t_cut = t.clone();
        t_cut.extend_from_slice(b"rayon-iter,all-pairs,seed,60,3,4,,,1,0.5");
        s.extend_from_slice(
            b"rayon-iter,all-pairs,seed,60,3,4,,,3,1.0,1.0,1.0,1.0,1.0,1.0,1.0,1.0,0,fa",
        );
        let r = repair(&t_cut, &s, &|_| Ok(())).unwrap();
        assert_eq!(r.finished.len(), 2);
        assert_eq!((r.dropped_trial_rows, r.dropped_summary_rows), (1, 1));
        assert_eq!(r.trials_csv, t);
    }

    #[test]
    fn a_summary_row_whose_trials_are_incomplete_makes_the_cell_run_again() {
        let (t, s) = two_cells();
        let text = String::from_utf8(t).unwrap();
        // Remove the last trial row of the second cell.
        let mut lines: Vec<&str> = text.lines().collect();
        lines.pop();
        let t = format!("{}\n", lines.join("\n"));
        let r = repair(t.as_bytes(), &s, &|_| Ok(())).unwrap();
        assert_eq!(r.finished.len(), 1);
        assert_eq!(r.finished[0].cores, 1);
        assert_eq!(
            (
                r.kept_trial_rows,
                r.dropped_trial_rows,
                r.dropped_summary_rows
            ),
            (3, 2, 1)
        );
    }

    #[test]
    fn repeated_rows_are_kept_once() {
        let (t, s) = two_cells();
        let text = String::from_utf8(t.clone()).unwrap();
        let last = text.lines().last().unwrap();
        let t2 = format!("{text}{last}\n");
        let stext = String::from_utf8(s.clone()).unwrap();
        let s2 = format!("{stext}{}\n", stext.lines().last().unwrap());
        let r = repair(t2.as_bytes(), s2.as_bytes(), &|_| Ok(())).unwrap();
        assert_eq!(r.finished.len(), 2);
        assert_eq!(r.trials_csv, t);
        assert_eq!(r.summary_csv, s);
    }

    #[test]
    fn missing_files_mean_nothing_is_finished() {
        let r = repair(b"", b"", &|_| Ok(())).unwrap();
        assert!(r.finished.is_empty());
        assert!(r.trials_csv.starts_with(b"strategy,"));
    }

    #[test]
    fn files_of_earlier_versions_are_read_and_upgraded_to_every_column() {
        let (t, s) = two_cells();
        // A file as an earlier version wrote it: its last `fewer` columns missing.
        let cut = |bytes: &[u8], fewer: usize| -> String {
            String::from_utf8(bytes.to_vec())
                .unwrap()
                .lines()
                .map(|l| {
                    let keep: Vec<&str> = l.split(',').collect();
                    format!("{}\n", keep[..keep.len() - fewer].join(","))
                })
                .collect()
        };
        // The upgrade writes every column: a missing `pin` as `none` (what these trials
        // have), a missing `passes_alone` empty (unknown), where these trials have 0.
        let upgraded_trials: String = String::from_utf8(t.clone())
            .unwrap()
            .lines()
            .map(|l| match l.strip_suffix(",0") {
                Some(row) => format!("{row},\n"),
                None => format!("{l}\n"), // the header
            })
            .collect();
        for (summary_fewer, trial_fewer) in [(2, 1), (3, 2)] {
            let older = cut(&s, summary_fewer);
            let older_trials = cut(&t, trial_fewer);
            let r = repair(older_trials.as_bytes(), older.as_bytes(), &|_| Ok(())).unwrap();
            assert!(r.upgraded, "{summary_fewer} {trial_fewer}");
            assert_eq!(r.finished.len(), 2);
            assert_eq!(r.summary_csv, s);
            assert_eq!(String::from_utf8(r.trials_csv).unwrap(), upgraded_trials);
        }
        assert!(!repair(&t, &s, &|_| Ok(())).unwrap().upgraded);
    }

    #[test]
    fn a_foreign_header_is_an_error() {
        let err = repair(b"a,b\n1,2\n", b"", &|_| Ok(())).unwrap_err();
        assert_eq!(err.file, "trials.csv");
        assert!(err.to_string().contains("'a,b'"), "{err}");
    }
}
