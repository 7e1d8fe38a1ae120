//! Writing `trials.csv` and `summary.csv` to any [`Write`]: runs as their contention windows
//! close, summary rows when their phase ends, each batch flushed at once.
//!
//! A phase's runs are written before its summary rows: a sweep killed in between leaves runs
//! without summary rows, which `--resume` keeps as the phase's finished runs and continues
//! (see [`crate::sweep::resume`]). A line cut off by a kill is dropped there.

use std::io::Write;

use super::rows::{SUMMARY_COLUMNS, SummaryRow, TRIAL_COLUMNS, TrialRow};

/// Writes cells to the two CSV streams.
#[derive(Debug)]
pub struct Exporter<T: Write, S: Write> {
    trials: csv::Writer<T>,
    summary: csv::Writer<S>,
}

impl<T: Write, S: Write> Exporter<T, S> {
    /// An exporter writing to `trials` and `summary`; with `headers`, the header lines are
    /// written (and flushed) now, so even a sweep stopped before its first cell leaves valid
    /// CSV files. Without, rows are appended to streams that already have them.
    pub fn new(trials: T, summary: S, headers: bool) -> csv::Result<Self> {
        let mut builder = csv::WriterBuilder::new();
        builder.has_headers(false);
        let mut e = Exporter {
            trials: builder.from_writer(trials),
            summary: builder.from_writer(summary),
        };
        if headers {
            e.trials.write_record(TRIAL_COLUMNS)?;
            e.summary.write_record(SUMMARY_COLUMNS)?;
            e.trials.flush()?;
            e.summary.flush()?;
        }
        Ok(e)
    }

    /// Writes runs' trial rows, flushed.
    pub fn write_trials(&mut self, trials: &[TrialRow]) -> csv::Result<()> {
        for row in trials {
            self.trials.serialize(row)?;
        }
        self.trials.flush()?;
        Ok(())
    }

    /// Writes a phase's summary rows, flushed.
    pub fn write_summaries(&mut self, rows: &[SummaryRow]) -> csv::Result<()> {
        for row in rows {
            self.summary.serialize(row)?;
        }
        self.summary.flush()?;
        Ok(())
    }
}

/// Rows as CSV bytes with the header line: what `--resume` writes back after repairs.
pub fn to_csv<R: serde::Serialize>(columns: &[&str], rows: &[R]) -> csv::Result<Vec<u8>> {
    let mut w = csv::WriterBuilder::new()
        .has_headers(false)
        .from_writer(Vec::new());
    w.write_record(columns)?;
    for row in rows {
        w.serialize(row)?;
    }
    w.into_inner().map_err(|e| e.into_error().into())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::results::fixtures;
    use crate::results::key::test_group;
    use crate::results::rows::Phase;
    use crate::results::summarize::{CellContext, summary_row};
    use crate::sweep::plan::Cell;
    use sph_solver::sph::neighbors::NeighborMode;
    use sph_strategies::StrategyName;

    fn cell() -> Cell {
        Cell {
            group: test_group(NeighborMode::Grid),
            strategy: StrategyName::RayonChunks,
            cores: 2,
            chunks: Some(5),
            pin: crate::topology::Pin::None,
        }
    }

    fn rows() -> (Vec<TrialRow>, SummaryRow) {
        let trials = fixtures::trials(&cell(), &[0.5, 0.25, 0.375]);
        let seq = fixtures::trials(&Cell::reference(cell().group), &[0.75, 0.5, 0.75]);
        let ctx = CellContext {
            hardware_threads: 2,
            shard: None,
            smt: None,
        };
        let summary = summary_row(&cell(), Phase::Grid, &trials, Some(&seq), None, &ctx);
        (trials, summary)
    }

    /// The header a serde-derived writer would produce for `row`.
    fn derived_header<R: serde::Serialize>(row: &R) -> String {
        let mut w = csv::Writer::from_writer(Vec::new());
        w.serialize(row).unwrap();
        let text = String::from_utf8(w.into_inner().unwrap()).unwrap();
        text.lines().next().unwrap().to_owned()
    }

    #[test]
    fn the_column_lists_match_the_row_structs() {
        let (trials, summary) = rows();
        assert_eq!(derived_header(&trials[0]), TRIAL_COLUMNS.join(","));
        assert_eq!(derived_header(&summary), SUMMARY_COLUMNS.join(","));
    }

    #[test]
    fn runs_and_summaries_are_written_as_exact_csv_lines() {
        let (trials, summary) = rows();
        let (mut t, mut s) = (Vec::new(), Vec::new());
        let mut e = Exporter::new(&mut t, &mut s, true).unwrap();
        e.write_trials(&trials[..2]).unwrap();
        e.write_summaries(std::slice::from_ref(&summary)).unwrap();
        drop(e);
        assert_eq!(
            String::from_utf8(t).unwrap(),
            format!(
                "{}\n\
                 rayon-chunks,grid,seed,60,3,2,5,12,1,0.5,1.0,00000000000000aa,ok,,0.005,0.0,0.25,none,\
                 grid,1,1,0.01,false\n\
                 rayon-chunks,grid,seed,60,3,2,5,12,2,0.25,0.5,00000000000000aa,ok,,0.0025,0.0,0.25,none,\
                 grid,2,1,0.01,false\n",
                TRIAL_COLUMNS.join(",")
            )
        );
        let line = String::from_utf8(s).unwrap();
        let line = line.lines().nth(1).unwrap();
        // Paired ratios 1.5, 2, 2: the speedup is their geometric mean.
        let speedup = (1.5f64 * 2.0 * 2.0).cbrt();
        assert!(
            line.starts_with(&format!(
                "rayon-chunks,grid,seed,60,3,2,5,12,3,0.375,0.125,0.25,0.375,0.5,0.75,{speedup},"
            )),
            "{line}"
        );
        assert!(line.ends_with(",false,,none,,grid"), "{line}");
    }

    #[test]
    fn appending_writes_no_header() {
        let (mut t, mut s) = (Vec::new(), Vec::new());
        Exporter::new(&mut t, &mut s, false).unwrap();
        assert!(t.is_empty() && s.is_empty());
    }

    #[test]
    fn to_csv_writes_the_header_then_the_rows() {
        let (trials, _) = rows();
        let bytes = to_csv(&TRIAL_COLUMNS, &trials).unwrap();
        let text = String::from_utf8(bytes).unwrap();
        assert_eq!(text.lines().count(), 4);
        assert!(text.starts_with("strategy,neighbors,"));
    }
}
