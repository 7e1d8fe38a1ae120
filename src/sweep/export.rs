//! Writing `trials.csv` and `summary.csv` to any [`Write`], a cell at a time.
//!
//! A cell's trial rows are written and flushed first, then its summary row: a sweep killed in
//! between leaves trial rows without a summary row, which `--resume` recognises as an
//! unfinished cell and drops (see [`super::resume`]). Nothing of a cell is written before the
//! cell has finished, so an interrupted cell leaves no rows at all.

use std::io::Write;

use crate::results::rows::{SUMMARY_COLUMNS, SummaryRow, TRIAL_COLUMNS, TrialRow};

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

    /// Writes one finished cell: its trial rows, flushed, then its summary row, flushed.
    pub fn write_cell(&mut self, trials: &[TrialRow], summary: &SummaryRow) -> csv::Result<()> {
        for row in trials {
            self.trials.serialize(row)?;
        }
        self.trials.flush()?;
        self.summary.serialize(summary)?;
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
    use crate::clock::Elapsed;
    use crate::contention::Foreign;
    use crate::results::key::test_group;
    use crate::sph::neighbors::NeighborMode;
    use crate::sweep::plan::Cell;
    use crate::sweep::rows::{Measured, summary_row, test_context, trial_rows};
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

    fn measured() -> Vec<Measured> {
        [(0.5, 1.0), (0.25, 0.5)]
            .iter()
            .map(|&(wall_s, cpu_s)| Measured {
                elapsed: Elapsed {
                    wall_s,
                    cpu_s,
                    foreign: Some(Foreign {
                        cpu_s: 0.01,
                        steal_s: Some(0.0),
                    }),
                },
                load1: Some(0.5),
                checksum: "0123456789abcdef".to_owned(),
            })
            .collect()
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
        let m = measured();
        let trials = trial_rows(&cell(), &m, None);
        let summary = summary_row(&cell(), &m, None, &test_context(Some(&[1.0]), 2));
        assert_eq!(derived_header(&trials[0]), TRIAL_COLUMNS.join(","));
        assert_eq!(derived_header(&summary), SUMMARY_COLUMNS.join(","));
    }

    #[test]
    fn a_cell_is_written_as_exact_csv_lines() {
        let m = measured();
        let (mut t, mut s) = (Vec::new(), Vec::new());
        let mut e = Exporter::new(&mut t, &mut s, true).unwrap();
        e.write_cell(
            &trial_rows(&cell(), &m, None),
            &summary_row(&cell(), &m, None, &test_context(Some(&[0.75, 0.75]), 2)),
        )
        .unwrap();
        drop(e);
        assert_eq!(
            String::from_utf8(t).unwrap(),
            format!(
                "{}\n\
                 rayon-chunks,grid,seed,60,3,2,5,12,1,0.5,1.0,0123456789abcdef,ok,,0.01,0.0,0.5,none,0\n\
                 rayon-chunks,grid,seed,60,3,2,5,12,2,0.25,0.5,0123456789abcdef,ok,,0.01,0.0,0.5,none,0\n",
                TRIAL_COLUMNS.join(",")
            )
        );
        // mean 0.375, stddev √0.03125, median 0.375, speedup 2, efficiency 1; resampled
        // means of two trials are 0.25, 0.375 or 0.5 (a quarter of them each at the ends),
        // so the interval spans 0.25..0.5 and the speedup's 0.75/0.5..0.75/0.25.
        assert_eq!(
            String::from_utf8(s).unwrap(),
            format!(
                "{}\n\
                 rayon-chunks,grid,seed,60,3,2,5,12,2,0.375,{},0.25,0.375,0.5,0.75,2.0,1.0,0,\
                 false,0123456789abcdef,ok,,0.25,0.5,1.5,3.0,0.01,false,,none,\n",
                SUMMARY_COLUMNS.join(","),
                0.03125f64.sqrt()
            )
        );
    }

    #[test]
    fn appending_writes_no_header() {
        let (mut t, mut s) = (Vec::new(), Vec::new());
        Exporter::new(&mut t, &mut s, false).unwrap();
        assert!(t.is_empty() && s.is_empty());
    }

    #[test]
    fn to_csv_writes_the_header_then_the_rows() {
        let m = measured();
        let rows = trial_rows(&cell(), &m, None);
        let bytes = to_csv(&TRIAL_COLUMNS, &rows).unwrap();
        let text = String::from_utf8(bytes).unwrap();
        assert_eq!(text.lines().count(), 3);
        assert!(text.starts_with("strategy,neighbors,"));
    }
}
