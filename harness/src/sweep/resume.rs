//! `--resume DIR`: what an earlier session finished, and the repairs that make each run
//! appear exactly once.
//!
//! A cell's phase ([`Phase`]) counts as finished when `summary.csv` has its row and
//! `trials.csv` has exactly `trials` rows for it (numbered 1, 2, …). The runs of a phase that
//! has no summary row yet are **pending**: each (cell, phase, round) is kept once, and the
//! runner skips those runs and continues the round it was in. Everything else — a line cut off
//! mid-write, a repeated row, a whole line that is not a row (a field too many, a status word
//! other than `ok` and `failed`: listed with why), a run the caller's check refuses — is
//! dropped, both files are written back without it, and the run happens again. Failed cells are finished too: their
//! failure is a result (delete their rows by hand to retry them).
//!
//! A finished cell is believed only if it passes [`crate::results::validate::cell`] (finite
//! positive times, statistics that are those of its trials) and the caller's own check
//! (`--resume`: the cell is in the plan and has the phase's number of rounds); a pending run
//! only if its times are possible and the caller's check of runs accepts it (its cell and round
//! are in the plan). Otherwise it is dropped, listed in [`Repaired::rejected`], and runs again.
//!
//! Directories written before rounds (their files lack `round` and the other columns after
//! `pin`) cannot be continued: their cells ran back to back, and a paired speedup needs the
//! rounds they do not have. Resuming one is refused with a message saying so.

use std::collections::{HashMap, HashSet};
use std::path::Path;

use anyhow::Context;

use super::plan::Cell;
use crate::io::capped;
use crate::results::export::to_csv;
use crate::results::key::Group;
use crate::results::rows::{
    Phase, SUMMARY_COLUMNS, SummaryRow, TRIAL_COLUMNS, TrialRow, is_older_summary_header,
    is_older_trial_header,
};
use crate::results::validate::unreadable;

/// Why a directory's files cannot be resumed.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum NotResumable {
    /// A header that is not a results file's.
    #[error(
        "{file} has the columns '{found}', not those bench-sph {} writes",
        crate::results::meta::VERSION
    )]
    UnexpectedColumns {
        /// The file's name.
        file: &'static str,
        /// Its header line.
        found: String,
    },
    /// A file an earlier version wrote, before rounds.
    #[error(
        "{file} was written by an earlier bench-sph, which ran each cell's trials back to back: \
         its cells have no rounds to pair and continue. Report it as it is (`bench-sph report \
         DIR`), or measure again in a new sweep"
    )]
    BeforeRounds {
        /// The file's name.
        file: &'static str,
    },
}

/// A caller's check of a finished cell's summary row.
pub type CheckCell<'a> = &'a dyn Fn(&SummaryRow) -> Result<(), String>;
/// A caller's check of a pending run.
pub type CheckRun<'a> = &'a dyn Fn(&TrialRow) -> Result<(), String>;

/// The finished cells and pending runs of a results directory, and its files with everything
/// else removed.
#[derive(Debug, Clone, PartialEq)]
pub struct Repaired {
    /// The summary rows of the finished cell phases, in file order.
    pub finished: Vec<SummaryRow>,
    /// The trial rows of the finished cell phases.
    pub finished_trials: Vec<TrialRow>,
    /// The runs of unfinished cell phases, each (cell, phase, round) once, in file order.
    pub pending: Vec<TrialRow>,
    /// Rows that were dropped although they were whole, and whole lines that are not rows:
    /// the cell, run or line, and why.
    pub rejected: Vec<String>,
    /// `trials.csv` as it should be: header, the finished cells' trial rows, the pending runs.
    pub trials_csv: Vec<u8>,
    /// `summary.csv` as it should be: header plus the finished cells' rows.
    pub summary_csv: Vec<u8>,
    /// Trial rows (or broken lines) dropped from `trials.csv`.
    pub dropped_trial_rows: usize,
    /// Summary rows (or broken lines) dropped from `summary.csv`.
    pub dropped_summary_rows: usize,
}

/// Repairs the contents of `trials.csv` and `summary.csv` (either may be empty: no file);
/// `check_cell` and `check_run` are the caller's own tests (see the module docs).
// Over ~60 lines on purpose: the repair is one pass over the rows whose steps (first row per
// cell, trials once per number, finished = complete and believed, the rest pending) are the
// module docs' list in order.
pub fn repair(
    trials: &[u8],
    summary: &[u8],
    check_cell: CheckCell<'_>,
    check_run: CheckRun<'_>,
) -> Result<Repaired, NotResumable> {
    let (summary_rows, mut dropped_summary_rows, unreadable_summary) = read_rows::<SummaryRow>(
        summary,
        "summary.csv",
        &SUMMARY_COLUMNS,
        is_older_summary_header,
    )?;
    let (trial_rows, mut dropped_trial_rows, unreadable_trials) =
        read_rows::<TrialRow>(trials, "trials.csv", &TRIAL_COLUMNS, is_older_trial_header)?;
    let mut rejected: Vec<String> = unreadable_summary
        .into_iter()
        .chain(unreadable_trials)
        .collect();

    // The first summary row of each cell phase; the trial rows of each, once per number.
    let mut seen = HashSet::new();
    let mut candidates = Vec::new();
    for row in summary_rows {
        if seen.insert(row.phased_key()) {
            candidates.push(row);
        } else {
            dropped_summary_rows += 1;
        }
    }
    // Each row with its place in the file, so that what is kept keeps its order.
    let mut by_cell: HashMap<(Cell, Phase), Vec<(usize, TrialRow)>> = HashMap::new();
    for (at, row) in trial_rows.into_iter().enumerate() {
        let rows = by_cell.entry(row.phased_key()).or_default();
        let repeated = rows
            .iter()
            .any(|(_, r)| r.trial == row.trial || (r.round.is_some() && r.round == row.round));
        if repeated {
            dropped_trial_rows += 1;
        } else {
            rows.push((at, row));
        }
    }

    // Finished = a summary row and trials numbered exactly 1..=trials.
    let mut finished = Vec::new();
    let mut kept: Vec<(usize, TrialRow)> = Vec::new();
    for row in candidates {
        let mut trials = by_cell.remove(&row.phased_key()).unwrap_or_default();
        trials.sort_by_key(|(_, t)| t.trial);
        let complete = trials.len() == row.trials
            && trials
                .iter()
                .enumerate()
                .all(|(i, (_, t))| t.trial == i + 1);
        let believed = if complete {
            let rows: Vec<TrialRow> = trials.iter().map(|(_, t)| t.clone()).collect();
            crate::results::validate::cell(&row, &rows).and_then(|()| check_cell(&row))
        } else {
            Ok(())
        };
        if let Err(why) = &believed {
            rejected.push(format!("{}: {why}", row.key().label_with_group()));
        }
        if complete && believed.is_ok() {
            kept.extend(trials);
            finished.push(row);
        } else if complete {
            dropped_trial_rows += trials.len();
            dropped_summary_rows += 1;
        } else {
            // A summary row written before its phase's last runs (or whose runs were cut):
            // the runs stay, as runs of an unfinished phase.
            by_cell.insert(row.phased_key(), trials);
            dropped_summary_rows += 1;
        }
    }

    // The rest are the runs of unfinished phases.
    let mut rest: Vec<(usize, TrialRow)> = by_cell.into_values().flatten().collect();
    rest.sort_by_key(|(at, _)| *at);
    let mut pending = Vec::new();
    for (at, run) in rest {
        match crate::results::validate::run(&run).and_then(|()| check_run(&run)) {
            Ok(()) => pending.push((at, run)),
            Err(why) => {
                rejected.push(format!(
                    "{}, round {}: {why}",
                    run.key().label_with_group(),
                    run.round.unwrap_or(run.trial)
                ));
                dropped_trial_rows += 1;
            }
        }
    }
    kept.sort_by_key(|(at, _)| *at);
    let kept: Vec<TrialRow> = kept.into_iter().map(|(_, t)| t).collect();
    let pending: Vec<TrialRow> = pending.into_iter().map(|(_, t)| t).collect();

    let csv_bytes = |result: csv::Result<Vec<u8>>| result.expect("CSV into memory cannot fail");
    let all_trials: Vec<&TrialRow> = kept.iter().chain(&pending).collect();
    Ok(Repaired {
        trials_csv: csv_bytes(to_csv(&TRIAL_COLUMNS, &all_trials)),
        summary_csv: csv_bytes(to_csv(&SUMMARY_COLUMNS, &finished)),
        finished,
        finished_trials: kept,
        pending,
        rejected,
        dropped_trial_rows,
        dropped_summary_rows,
    })
}

impl Repaired {
    /// The same directory without the rows of `groups` — of every phase, or of `phase` only:
    /// those run again from their first round. Returns the rows removed.
    pub fn without_groups(&mut self, groups: &HashSet<Group>, phase: Option<Phase>) -> usize {
        let before = self.finished.len() + self.finished_trials.len() + self.pending.len();
        let gone =
            |group: Group, of: Phase| groups.contains(&group) && phase.is_none_or(|p| p == of);
        self.finished.retain(|r| !gone(r.group(), r.phase));
        self.finished_trials.retain(|r| !gone(r.group(), r.phase));
        self.pending.retain(|r| !gone(r.group(), r.phase));
        let after = self.finished.len() + self.finished_trials.len() + self.pending.len();
        let csv_bytes = |result: csv::Result<Vec<u8>>| result.expect("CSV into memory cannot fail");
        let all_trials: Vec<&TrialRow> = self.finished_trials.iter().chain(&self.pending).collect();
        self.trials_csv = csv_bytes(to_csv(&TRIAL_COLUMNS, &all_trials));
        self.summary_csv = csv_bytes(to_csv(&SUMMARY_COLUMNS, &self.finished));
        before - after
    }
}

/// The complete rows of a CSV file, the number of lines that were not (a last line without
/// its newline, cut off by a kill, or a row that does not parse), and a note saying why for
/// each whole line that is not a row (too many or too few fields, a status word other than
/// `ok` and `failed`, …). A header that `older` accepts is an earlier version's file, which
/// cannot be resumed.
fn read_rows<R: serde::de::DeserializeOwned>(
    bytes: &[u8],
    file: &'static str,
    columns: &[&str],
    older: fn(&[&str]) -> bool,
) -> Result<(Vec<R>, usize, Vec<String>), NotResumable> {
    let complete = match bytes.iter().rposition(|&b| b == b'\n') {
        Some(last) => &bytes[..=last],
        None => &[][..],
    };
    let mut dropped = usize::from(complete.len() < bytes.len());
    if complete.is_empty() {
        return Ok((Vec::new(), dropped, Vec::new()));
    }
    let mut reader = csv::ReaderBuilder::new()
        .has_headers(true)
        .flexible(true)
        .from_reader(complete);
    let first_line = || {
        String::from_utf8_lossy(complete.split(|&b| b == b'\n').next().unwrap_or_default())
            .into_owned()
    };
    match reader.headers() {
        Ok(h) => {
            let found: Vec<&str> = h.iter().collect();
            if older(&found) {
                return Err(NotResumable::BeforeRounds { file });
            }
            if found != columns {
                return Err(NotResumable::UnexpectedColumns {
                    file,
                    found: found.join(","),
                });
            }
        }
        Err(_) => {
            return Err(NotResumable::UnexpectedColumns {
                file,
                found: first_line(),
            });
        }
    }
    let header = csv::StringRecord::from(columns.to_vec());
    let line =
        |p: Option<&csv::Position>| p.map_or_else(|| "?".to_owned(), |p| p.line().to_string());
    let mut rows = Vec::new();
    let mut notes = Vec::new();
    for record in reader.records() {
        let why = match record {
            Err(e) => Some((line(e.position()), unreadable(&e, columns))),
            Ok(r) if r.len() != columns.len() => Some((
                line(r.position()),
                format!("it has {} fields, not {}", r.len(), columns.len()),
            )),
            Ok(r) => match r.deserialize::<R>(Some(&header)) {
                Ok(row) => {
                    rows.push(row);
                    None
                }
                Err(e) => Some((line(r.position()), unreadable(&e, columns))),
            },
        };
        if let Some((at, why)) = why {
            dropped += 1;
            notes.push(format!("{file} line {at}: not a bench-sph row ({why})"));
        }
    }
    Ok((rows, dropped, notes))
}

/// Reads `dir`'s CSV files (a missing one counts as empty), repairs them with `check`, and
/// writes the repaired contents back (each through a temporary file renamed over the
/// original).
pub fn load_and_repair(
    dir: &Path,
    check_cell: CheckCell<'_>,
    check_run: CheckRun<'_>,
) -> anyhow::Result<Repaired> {
    // Regular files within their caps only (see `capped`); a missing one is empty.
    let read = |name: &str, kind| -> anyhow::Result<Vec<u8>> {
        Ok(capped::read_if_exists(&dir.join(name), kind)?.unwrap_or_default())
    };
    let repaired = repair(
        &read("trials.csv", capped::TRIALS_CSV)?,
        &read("summary.csv", capped::SUMMARY_CSV)?,
        check_cell,
        check_run,
    )
    .with_context(|| format!("cannot resume '{}'", dir.display()))?;
    write_back(dir, &repaired)?;
    Ok(repaired)
}

/// Writes `repaired`'s files into `dir` (each through a temporary file renamed over the
/// original).
pub fn write_back(dir: &Path, repaired: &Repaired) -> anyhow::Result<()> {
    for (name, bytes) in [
        ("trials.csv", &repaired.trials_csv),
        ("summary.csv", &repaired.summary_csv),
    ] {
        crate::output::atomic::write(&dir.join(name), bytes)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::results::export::Exporter;
    use crate::results::fixtures;
    use crate::results::key::test_group;
    use crate::results::rows::Status;
    use crate::results::summarize::{CellContext, summary_row};
    use crate::sweep::plan::Cell;
    use sph_solver::sph::neighbors::NeighborMode;
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

    fn summary(cell: &Cell, trials: &[TrialRow]) -> SummaryRow {
        let ctx = CellContext {
            hardware_threads: 2,
            shard: None,
            smt: None,
        };
        summary_row(cell, Phase::Grid, trials, None, None, &ctx)
    }

    fn accept_cell(_: &SummaryRow) -> Result<(), String> {
        Ok(())
    }

    fn accept_run(_: &TrialRow) -> Result<(), String> {
        Ok(())
    }

    /// A finished phase of two cells (3 rounds each), as an uninterrupted session writes it.
    fn finished_phase() -> (Vec<u8>, Vec<u8>) {
        let (mut t, mut s) = (Vec::new(), Vec::new());
        let mut e = Exporter::new(&mut t, &mut s, true).unwrap();
        let runs: Vec<Vec<TrialRow>> = [1, 2]
            .iter()
            .map(|&c| fixtures::trials(&cell(c), &[1.0, 2.0, 3.0]))
            .collect();
        for (first, second) in runs[0].iter().zip(&runs[1]) {
            e.write_trials(&[first.clone(), second.clone()]).unwrap();
        }
        e.write_summaries(&[summary(&cell(1), &runs[0]), summary(&cell(2), &runs[1])])
            .unwrap();
        drop(e);
        (t, s)
    }

    fn repair_all(t: &[u8], s: &[u8]) -> Repaired {
        repair(t, s, &accept_cell, &accept_run).unwrap()
    }

    #[test]
    fn intact_files_come_back_unchanged() {
        let (t, s) = finished_phase();
        let r = repair_all(&t, &s);
        assert_eq!(r.rejected, Vec::<String>::new());
        assert_eq!(r.dropped_summary_rows, 0);
        assert_eq!(r.finished.len(), 2);
        assert_eq!((r.finished_trials.len(), r.pending.len()), (6, 0));
        assert_eq!((r.dropped_trial_rows, r.dropped_summary_rows), (0, 0));
        assert_eq!(r.trials_csv, t);
        assert_eq!(r.summary_csv, s);
    }

    #[test]
    fn runs_of_a_phase_without_summary_rows_are_kept_as_pending() {
        let (t, _) = finished_phase();
        let empty = to_csv(&SUMMARY_COLUMNS, &Vec::<SummaryRow>::new()).unwrap();
        let r = repair_all(&t, &empty);
        assert!(r.finished.is_empty());
        assert_eq!(r.pending.len(), 6);
        assert_eq!(r.trials_csv, t, "every run kept, once");
        let rounds: Vec<Option<usize>> = r.pending.iter().map(|t| t.round).collect();
        assert_eq!(
            rounds,
            [Some(1), Some(1), Some(2), Some(2), Some(3), Some(3)]
        );
    }

    #[test]
    fn a_line_cut_off_mid_write_and_a_repeated_run_are_dropped() {
        let (t, s) = finished_phase();
        let text = String::from_utf8(t.clone()).unwrap();
        let repeated = text.lines().nth(3).unwrap();
        let mut t2 = format!("{text}{repeated}\n").into_bytes();
        t2.extend_from_slice(b"rayon-iter,all-pairs,seed,60,3,4,,,1,0.5");
        let r = repair_all(&t2, &s);
        assert_eq!(r.finished.len(), 2);
        assert_eq!(r.dropped_trial_rows, 2);
        assert_eq!(r.trials_csv, t);
    }

    #[test]
    fn a_summary_row_whose_runs_are_incomplete_leaves_its_runs_pending() {
        let (t, s) = finished_phase();
        let text = String::from_utf8(t).unwrap();
        // Remove the last run of the second cell.
        let mut lines: Vec<&str> = text.lines().collect();
        lines.pop();
        let t = format!("{}\n", lines.join("\n"));
        let r = repair_all(t.as_bytes(), &s);
        assert_eq!(r.finished.len(), 1);
        assert_eq!(r.finished[0].cores, 1);
        assert_eq!((r.pending.len(), r.dropped_summary_rows), (2, 1));
    }

    #[test]
    fn a_run_the_caller_refuses_or_with_impossible_times_runs_again() {
        let (t, _) = finished_phase();
        let empty = to_csv(&SUMMARY_COLUMNS, &Vec::<SummaryRow>::new()).unwrap();
        let not_round_3 = |r: &TrialRow| match r.round {
            Some(3) => Err("not a round of the plan".to_owned()),
            _ => Ok(()),
        };
        let r = repair(&t, &empty, &accept_cell, &not_round_3).unwrap();
        assert_eq!((r.pending.len(), r.dropped_trial_rows), (4, 2));
        assert!(
            r.rejected[0].contains("round 3: not a round of the plan"),
            "{:?}",
            r.rejected
        );
        let text = String::from_utf8(t)
            .unwrap()
            .replacen(",1.0,2.0,", ",-1.0,2.0,", 1);
        let r = repair_all(text.as_bytes(), &empty);
        assert_eq!(r.pending.len(), 5);
        assert!(r.rejected[0].contains("wall_s = -1"), "{:?}", r.rejected);
    }

    #[test]
    fn a_whole_line_that_is_not_a_row_is_dropped_saying_why() {
        let (t, s) = finished_phase();
        let text = String::from_utf8(t).unwrap();
        let mut lines: Vec<String> = text.lines().map(str::to_owned).collect();
        lines[2] = lines[2].replacen(",ok,", ",boom,", 1);
        lines[3] = lines[3].replacen(",ok,", ",failed,boom,", 1);
        let edited = format!("{}\n", lines.join("\n"));
        let r = repair_all(edited.as_bytes(), &s);
        assert_eq!(r.finished.len(), 0, "both cells lost a run");
        assert!(
            r.rejected[0].starts_with("trials.csv line 3: not a bench-sph row (")
                && r.rejected[0].contains("status 'boom' is neither ok nor failed"),
            "{:?}",
            r.rejected
        );
        assert_eq!(
            r.rejected[1],
            "trials.csv line 4: not a bench-sph row (it has 24 fields, not 23)"
        );
    }

    #[test]
    fn a_failed_run_stays_pending_with_its_reason() {
        let mut runs = fixtures::trials(&cell(1), &[1.0, 2.0]);
        runs[1].status = Status::Failed;
        runs[1].reason = "round 2: checksum differs".to_owned();
        let t = to_csv(&TRIAL_COLUMNS, &runs).unwrap();
        let r = repair_all(&t, b"");
        assert_eq!(r.pending[1].status, Status::Failed);
    }

    #[test]
    fn removing_groups_drops_all_their_rows() {
        let (t, s) = finished_phase();
        let mut r = repair_all(&t, &s);
        let groups: HashSet<Group> = [cell(1).group].into();
        assert_eq!(r.without_groups(&groups, Some(Phase::Confirm)), 0);
        assert_eq!(r.without_groups(&groups, None), 8);
        assert!(r.finished.is_empty() && r.finished_trials.is_empty());
        assert_eq!(String::from_utf8(r.trials_csv).unwrap().lines().count(), 1);
    }

    #[test]
    fn missing_files_mean_nothing_is_finished() {
        let r = repair_all(b"", b"");
        assert!(r.finished.is_empty());
        assert!(r.trials_csv.starts_with(b"strategy,"));
    }

    #[test]
    fn files_written_before_rounds_are_refused_as_such() {
        let (t, s) = finished_phase();
        let before: String = String::from_utf8(t)
            .unwrap()
            .lines()
            .map(|l| {
                let keep: Vec<&str> = l.split(',').collect();
                let last = if keep[0] == "strategy" {
                    "passes_alone"
                } else {
                    "0"
                };
                format!("{},{last}\n", keep[..18].join(","))
            })
            .collect();
        let err = repair(before.as_bytes(), &s, &accept_cell, &accept_run).unwrap_err();
        assert_eq!(err, NotResumable::BeforeRounds { file: "trials.csv" });
        assert!(err.to_string().contains("back to back"), "{err}");
        let summary_before: String = String::from_utf8(s)
            .unwrap()
            .lines()
            .map(|l| l.rsplit_once(',').unwrap().0.to_owned() + "\n")
            .collect();
        let err = repair(b"", summary_before.as_bytes(), &accept_cell, &accept_run).unwrap_err();
        assert_eq!(
            err,
            NotResumable::BeforeRounds {
                file: "summary.csv"
            }
        );
    }

    #[test]
    fn a_foreign_header_is_an_error() {
        let err = repair(b"a,b\n1,2\n", b"", &accept_cell, &accept_run).unwrap_err();
        assert!(err.to_string().contains("'a,b'"), "{err}");
    }
}
