//! `--init FILE.csv`: a header row, columns `x,y` required, `vx,vy` optional (default 0),
//! other columns ignored; one particle per row. Lines starting with `#` are comments; a
//! dump's first line ([`DumpInfo`]) is read back into [`InitRows::dumped`].
//!
//! Reading is bounded, so that any path ends quickly: a line may hold at most
//! [`MAX_LINE_BYTES`](crate::io::bounded::MAX_LINE_BYTES) (4096) bytes and the file at most
//! [`MAX_LINES`] lines (the most particles any command accepts, a header and
//! [`MAX_COMMENT_LINES`] comments). `/dev/zero` is refused after 4 KiB; a directory is refused
//! before reading.

use std::path::Path;

use serde::Deserialize;

use crate::MAX_PARTICLES;
use crate::io::bounded::{BoundedLines, Overrun, overrun};
use crate::io::dump_csv::DumpInfo;
use crate::sph::state::{Domain, State};

/// Comment lines an init file may hold besides its header and particles.
pub const MAX_COMMENT_LINES: u64 = 1000;

/// The most lines an init file may hold.
pub const MAX_LINES: u64 = MAX_PARTICLES as u64 + 1 + MAX_COMMENT_LINES;

/// What is wrong with an init file. Line numbers are 1-based and count the header.
#[derive(Debug, thiserror::Error)]
pub enum InitError {
    /// The file could not be opened or read.
    #[error("cannot read init file '{path}'")]
    Io {
        /// The file.
        path: String,
        /// The OS error.
        source: std::io::Error,
    },
    /// The path is a directory.
    #[error("init file '{path}' is a directory, not a CSV file")]
    Directory {
        /// The path.
        path: String,
    },
    /// The file is not a CSV file of ours: a line too long, or too many lines.
    #[error("init file '{path}': {overrun}")]
    Overrun {
        /// The file.
        path: String,
        /// What was too large.
        overrun: Overrun,
    },
    /// The file has no header, or a header and no rows.
    #[error(
        "init file '{path}' holds no particles (it needs a header row and at least one data row)"
    )]
    Empty {
        /// The file.
        path: String,
    },
    /// A required column is missing from the header.
    #[error("init file '{path}' line 1: missing column '{column}' (the header must name x and y)")]
    MissingColumn {
        /// The file.
        path: String,
        /// The missing column's name.
        column: &'static str,
    },
    /// A row could not be parsed as CSV (e.g. a different number of fields).
    #[error("init file '{path}' line {line}: {message}")]
    Malformed {
        /// The file.
        path: String,
        /// Line of the row.
        line: u64,
        /// The CSV reader's message.
        message: String,
    },
    /// A cell is not a finite number.
    #[error("init file '{path}' line {line}, column '{column}': '{value}' is not a finite number")]
    BadNumber {
        /// The file.
        path: String,
        /// Line of the row.
        line: u64,
        /// The column.
        column: &'static str,
        /// The cell as written.
        value: String,
    },
    /// A particle lies outside the tank.
    #[error(
        "init file '{path}' line {line}: particle at ({x}, {y}) is outside the walls \
         [0, {width}] x [0, {height}] of this preset's tank for {n} particles"
    )]
    OutsideWalls {
        /// The file.
        path: String,
        /// Line of the row.
        line: u64,
        /// The particle's x.
        x: f64,
        /// The particle's y.
        y: f64,
        /// Tank width.
        width: f64,
        /// Tank height.
        height: f64,
        /// Particle count that fixed the tank.
        n: usize,
    },
}

/// Positions and velocities read from a file, with the line each particle came from.
#[derive(Debug, Clone, PartialEq)]
pub struct InitRows {
    /// The particles, forces and densities zero.
    pub state: State,
    /// The 1-based line of each particle.
    pub lines: Vec<u64>,
    /// What the file's first line says about the run that dumped it, if it is a dump.
    pub dumped: Option<DumpInfo>,
}

/// One row as the file writes it. Cells stay text until [`number`] parses them, so that a bad
/// cell is reported with its column and as written, and its value keeps every bit
/// (`str::parse::<f64>` rounds exactly). `vx`/`vy` are `None` only when the header lacks the
/// column (then 0); an empty cell in a present column is an error like any non-number.
#[derive(Debug, Deserialize)]
struct Row {
    x: String,
    y: String,
    #[serde(default, deserialize_with = "present")]
    vx: Option<String>,
    #[serde(default, deserialize_with = "present")]
    vy: Option<String>,
}

/// A cell of a column the header has, even an empty one (csv reads an empty cell as `None`).
fn present<'de, D: serde::Deserializer<'de>>(cell: D) -> Result<Option<String>, D::Error> {
    String::deserialize(cell).map(Some)
}

/// A CSV reader of `path` (shown as `shown`) past its header, and the header, which names at
/// least the columns `x` and `y`.
fn open(
    path: &Path,
    shown: &str,
) -> Result<(csv::Reader<BoundedLines<std::fs::File>>, csv::StringRecord), InitError> {
    let io = |source| InitError::Io {
        path: shown.to_owned(),
        source,
    };
    if std::fs::metadata(path).map_err(io)?.is_dir() {
        return Err(InitError::Directory {
            path: shown.to_owned(),
        });
    }
    let file = std::fs::File::open(path).map_err(io)?;
    let mut reader = csv::ReaderBuilder::new()
        .trim(csv::Trim::All)
        .comment(Some(b'#'))
        .from_reader(BoundedLines::new(file, MAX_LINES));
    let headers = reader.headers().map_err(|e| malformed(e, shown))?.clone();
    if headers.is_empty() || headers.iter().all(str::is_empty) {
        return Err(InitError::Empty {
            path: shown.to_owned(),
        });
    }
    if let Some(column) = ["x", "y"]
        .into_iter()
        .find(|&c| !headers.iter().any(|h| h == c))
    {
        return Err(InitError::MissingColumn {
            path: shown.to_owned(),
            column,
        });
    }
    Ok((reader, headers))
}

/// Reads `path`. Checks numbers, not walls (the tank depends on N; see [`check_walls`]).
pub fn read(path: &Path) -> Result<InitRows, InitError> {
    let shown = path.display().to_string();
    let (mut reader, headers) = open(path, &shown)?;
    let (mut x, mut y, mut vx, mut vy, mut lines) = (vec![], vec![], vec![], vec![], vec![]);
    for record in reader.records() {
        let record = record.map_err(|e| malformed(e, &shown))?;
        let line = record.position().map_or(0, |p| p.line());
        let row: Row = record
            .deserialize(Some(&headers))
            .map_err(|e| InitError::Malformed {
                path: shown.clone(),
                line,
                message: e.to_string(),
            })?;
        let cell = |text: Option<&str>, column| number(text, column, &shown, line);
        x.push(cell(Some(&row.x), "x")?);
        y.push(cell(Some(&row.y), "y")?);
        vx.push(cell(row.vx.as_deref(), "vx")?);
        vy.push(cell(row.vy.as_deref(), "vy")?);
        lines.push(line);
    }
    if x.is_empty() {
        return Err(InitError::Empty { path: shown });
    }
    let dumped = DumpInfo::parse(&String::from_utf8_lossy(reader.get_ref().first_line()));
    let n = x.len();
    let state = State::try_from_kinematics(x, y, vx, vy).map_err(|e| InitError::Io {
        path: shown,
        source: std::io::Error::new(
            std::io::ErrorKind::OutOfMemory,
            format!("no memory for {n} particles: {e}"),
        ),
    })?;
    Ok(InitRows {
        state,
        lines,
        dumped,
    })
}

/// A cell's finite value (0 for a column the file does not have).
fn number(
    text: Option<&str>,
    column: &'static str,
    path: &str,
    line: u64,
) -> Result<f64, InitError> {
    let Some(text) = text else { return Ok(0.0) };
    match text.parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        _ => Err(InitError::BadNumber {
            path: path.to_owned(),
            line,
            column,
            value: text.to_owned(),
        }),
    }
}

/// A CSV reader's error as the init file's: an over-long line or file, an I/O error, or a
/// malformed row with its line.
fn malformed(e: csv::Error, path: &str) -> InitError {
    let (line, message) = (e.position().map_or(0, |p| p.line()), e.to_string());
    match e.into_kind() {
        csv::ErrorKind::Io(source) => match overrun(&source) {
            Some(overrun) => InitError::Overrun {
                path: path.to_owned(),
                overrun,
            },
            None => InitError::Io {
                path: path.to_owned(),
                source,
            },
        },
        _ => InitError::Malformed {
            path: path.to_owned(),
            line,
            message,
        },
    }
}

/// Checks that every particle lies inside `domain`'s walls (0 ≤ x ≤ width, 0 ≤ y ≤ height).
pub fn check_walls(path: &Path, rows: &InitRows, domain: Domain) -> Result<(), InitError> {
    let s = &rows.state;
    let outside = (0..s.len()).find(|&i| {
        !(0.0..=domain.width).contains(&s.x[i]) || !(0.0..=domain.height).contains(&s.y[i])
    });
    match outside {
        None => Ok(()),
        Some(i) => Err(InitError::OutsideWalls {
            path: path.display().to_string(),
            line: rows.lines[i],
            x: s.x[i],
            y: s.y[i],
            width: domain.width,
            height: domain.height,
            n: s.len(),
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Reads an init file holding `text`.
    fn read_text(text: &str) -> Result<InitRows, InitError> {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("init.csv");
        std::fs::write(&path, text).unwrap();
        read(&path)
    }

    #[test]
    fn columns_are_found_by_name_in_any_order_and_missing_velocities_are_zero() {
        let rows = read_text("# a comment\nid,y,x\n7,2.5,1.5\n8,4,3\n").unwrap();
        assert_eq!(rows.state.x, [1.5, 3.0]);
        assert_eq!(rows.state.y, [2.5, 4.0]);
        assert_eq!(rows.state.vx, [0.0, 0.0]);
        assert_eq!(rows.lines, [3, 4]);
    }

    #[test]
    fn every_bit_of_a_written_value_is_read_back() {
        let v: f64 = 0.1 + 0.2;
        let rows = read_text(&format!("x,y,vx,vy\n{v:?},1,{:?},-0\n", -v / 3.0)).unwrap();
        assert_eq!(rows.state.x[0].to_bits(), v.to_bits());
        assert_eq!(rows.state.vx[0].to_bits(), (-v / 3.0).to_bits());
        assert_eq!(rows.state.vy[0].to_bits(), (-0.0f64).to_bits());
    }

    #[test]
    fn an_empty_cell_of_a_present_column_is_an_error_naming_its_line_and_column() {
        let err = read_text("x,y,vx\n1,2,3\n1,2,\n").unwrap_err().to_string();
        assert!(
            err.ends_with("line 3, column 'vx': '' is not a finite number"),
            "{err}"
        );
        let err = read_text("x,vx\n1,2\n").unwrap_err().to_string();
        assert!(err.ends_with("line 1: missing column 'y' (the header must name x and y)"));
    }
}
