//! `--init FILE.csv`: a header row, columns `x,y` required, `vx,vy` optional (default 0),
//! other columns ignored; one particle per row.

use std::path::Path;

use crate::sph::state::{Domain, State};

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
}

/// Reads `path`. Checks numbers, not walls (the tank depends on N; see [`check_walls`]).
pub fn read(path: &Path) -> Result<InitRows, InitError> {
    let shown = path.display().to_string();
    let file = std::fs::File::open(path).map_err(|source| InitError::Io {
        path: shown.clone(),
        source,
    })?;
    let mut reader = csv::ReaderBuilder::new()
        .trim(csv::Trim::All)
        .from_reader(std::io::BufReader::new(file));
    let malformed = |e: csv::Error, shown: &str| InitError::Malformed {
        path: shown.to_owned(),
        line: e.position().map_or(0, |p| p.line()),
        message: e.to_string(),
    };
    let headers = reader.headers().map_err(|e| malformed(e, &shown))?.clone();
    if headers.is_empty() || headers.iter().all(str::is_empty) {
        return Err(InitError::Empty { path: shown });
    }
    let column = |name: &'static str| headers.iter().position(|h| h == name);
    let cx = column("x").ok_or(InitError::MissingColumn {
        path: shown.clone(),
        column: "x",
    })?;
    let cy = column("y").ok_or(InitError::MissingColumn {
        path: shown.clone(),
        column: "y",
    })?;
    let (cvx, cvy) = (column("vx"), column("vy"));

    let (mut x, mut y, mut vx, mut vy, mut lines) = (vec![], vec![], vec![], vec![], vec![]);
    for record in reader.records() {
        let record = record.map_err(|e| malformed(e, &shown))?;
        let line = record.position().map_or(0, |p| p.line());
        let cell = |idx: Option<usize>, name: &'static str| -> Result<f64, InitError> {
            let Some(idx) = idx else { return Ok(0.0) };
            let text = record.get(idx).unwrap_or("");
            match text.parse::<f64>() {
                Ok(v) if v.is_finite() => Ok(v),
                _ => Err(InitError::BadNumber {
                    path: shown.clone(),
                    line,
                    column: name,
                    value: text.to_owned(),
                }),
            }
        };
        x.push(cell(Some(cx), "x")?);
        y.push(cell(Some(cy), "y")?);
        vx.push(cell(cvx, "vx")?);
        vy.push(cell(cvy, "vy")?);
        lines.push(line);
    }
    if x.is_empty() {
        return Err(InitError::Empty { path: shown });
    }
    Ok(InitRows {
        state: State::from_kinematics(x, y, vx, vy),
        lines,
    })
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
