//! The experiment: Martin & Moyce (1952), Phil. Trans. R. Soc. Lond. A 244, 312–324, the
//! collapse of a square water column (n² = 2, a = 2.25 in). Two tables ship in the binary as
//! the CSV files beside this module (`data/`, each with a header comment naming its source)
//! and are parsed at run time:
//!
//! - the surge front: Z = x_front / a against T = t √(2g/a);
//! - the residual column at the wall: H = h / (2a) against τ = t √(g/a).

use thiserror::Error;

/// The surge-front table's text: `T,Z` after `#` comments.
const SURGE_FRONT_CSV: &str = include_str!("data/martin_moyce_1952_surge_front.csv");
/// The column-height table's text: `tau,H` after `#` comments.
const COLUMN_HEIGHT_CSV: &str = include_str!("data/martin_moyce_1952_column_height.csv");

/// Why a table did not parse (the tables ship in the binary, so this is a bug of the build).
#[derive(Debug, Error, PartialEq)]
pub enum DataError {
    /// The first line that is not a comment is not the expected header.
    #[error("table {table}: header {found:?}, expected {expected:?}")]
    Header {
        /// The table's file name.
        table: &'static str,
        /// The header found.
        found: String,
        /// The header expected.
        expected: &'static str,
    },
    /// A row is not two finite numbers.
    #[error("table {table}, line {line}: {text:?} is not two finite numbers")]
    Row {
        /// The table's file name.
        table: &'static str,
        /// 1-based line number.
        line: usize,
        /// The line.
        text: String,
    },
    /// The rows are not in strictly increasing order of their first column.
    #[error("table {table}, line {line}: times must increase")]
    Order {
        /// The table's file name.
        table: &'static str,
        /// 1-based line number.
        line: usize,
    },
    /// The table has no rows.
    #[error("table {table} has no rows")]
    Empty {
        /// The table's file name.
        table: &'static str,
    },
}

/// One measured point: a dimensionless time and the dimensionless quantity at it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Point {
    /// T (surge front) or τ (column height), dimensionless.
    pub time: f64,
    /// Z (surge front) or H (column height), dimensionless.
    pub value: f64,
}

/// Both tables.
#[derive(Debug, Clone, PartialEq)]
pub struct Experiment {
    /// Z against T, T increasing.
    pub surge_front: Vec<Point>,
    /// H against τ, τ increasing.
    pub column_height: Vec<Point>,
}

/// The tables shipped in the binary.
pub fn experiment() -> Result<Experiment, DataError> {
    Ok(Experiment {
        surge_front: parse("martin_moyce_1952_surge_front.csv", "T,Z", SURGE_FRONT_CSV)?,
        column_height: parse(
            "martin_moyce_1952_column_height.csv",
            "tau,H",
            COLUMN_HEIGHT_CSV,
        )?,
    })
}

/// Parses a table: lines starting with `#` are comments, then `header`, then one `time,value`
/// row per line (blank lines skipped), times strictly increasing.
fn parse(table: &'static str, header: &'static str, text: &str) -> Result<Vec<Point>, DataError> {
    let mut lines = text
        .lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.trim()))
        .filter(|(_, l)| !l.is_empty() && !l.starts_with('#'));
    match lines.next() {
        Some((_, found)) if found == header => {}
        found => {
            return Err(DataError::Header {
                table,
                found: found.map_or_else(String::new, |(_, l)| l.to_owned()),
                expected: header,
            });
        }
    }
    let mut points: Vec<Point> = Vec::new();
    for (line, text) in lines {
        let bad = || DataError::Row {
            table,
            line,
            text: text.to_owned(),
        };
        let (a, b) = text.split_once(',').ok_or_else(bad)?;
        let number = |s: &str| s.trim().parse::<f64>().ok().filter(|v| v.is_finite());
        let (Some(time), Some(value)) = (number(a), number(b)) else {
            return Err(bad());
        };
        if points.last().is_some_and(|p| p.time >= time) {
            return Err(DataError::Order { table, line });
        }
        points.push(Point { time, value });
    }
    if points.is_empty() {
        return Err(DataError::Empty { table });
    }
    Ok(points)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pairs(points: &[Point]) -> Vec<(f64, f64)> {
        points.iter().map(|p| (p.time, p.value)).collect()
    }

    #[test]
    fn the_shipped_tables_parse_to_exactly_martin_and_moyces_values() {
        let e = experiment().unwrap();
        let t = [
            0.41, 0.84, 1.19, 1.43, 1.63, 1.83, 1.98, 2.20, 2.32, 2.51, 2.65, 2.83, 2.98, 3.11,
            3.33,
        ];
        let z = [
            1.11, 1.22, 1.44, 1.67, 1.89, 2.11, 2.33, 2.56, 2.78, 3.00, 3.22, 3.44, 3.67, 3.89,
            4.11,
        ];
        let expected: Vec<(f64, f64)> = t.into_iter().zip(z).collect();
        assert_eq!(pairs(&e.surge_front), expected);
        let tau = [
            0.56, 0.77, 0.93, 1.08, 1.28, 1.46, 1.66, 1.84, 2.00, 2.21, 2.45, 2.70, 3.06, 3.44,
            4.20, 5.25, 7.40,
        ];
        let h = [
            0.94, 0.89, 0.83, 0.78, 0.72, 0.67, 0.61, 0.56, 0.50, 0.44, 0.39, 0.33, 0.28, 0.22,
            0.17, 0.11, 0.06,
        ];
        let expected: Vec<(f64, f64)> = tau.into_iter().zip(h).collect();
        assert_eq!(pairs(&e.column_height), expected);
    }

    #[test]
    fn the_shipped_tables_name_their_source() {
        for text in [SURGE_FRONT_CSV, COLUMN_HEIGHT_CSV] {
            assert!(
                text.starts_with("# Martin, J. C. & Moyce, W. J. (1952)"),
                "{text}"
            );
            assert!(text.contains("Phil. Trans. R. Soc. Lond. A 244"), "{text}");
        }
    }

    #[test]
    fn a_bad_header_row_or_order_is_an_error_naming_the_line() {
        let p = |text| parse("t.csv", "T,Z", text);
        assert_eq!(
            p("# c\nT,X\n1,2\n"),
            Err(DataError::Header {
                table: "t.csv",
                found: "T,X".into(),
                expected: "T,Z"
            })
        );
        assert_eq!(
            p("T,Z\n1,2\n2,x\n"),
            Err(DataError::Row {
                table: "t.csv",
                line: 3,
                text: "2,x".into()
            })
        );
        assert!(matches!(
            p("T,Z\n1,inf\n"),
            Err(DataError::Row { line: 2, .. })
        ));
        assert_eq!(
            p("T,Z\n2,1\n1,1\n"),
            Err(DataError::Order {
                table: "t.csv",
                line: 3
            })
        );
        assert_eq!(p("T,Z\n"), Err(DataError::Empty { table: "t.csv" }));
        assert_eq!(
            pairs(&p("# c\n\nT,Z\n1, 2\n").unwrap()),
            [(1.0, 2.0)],
            "blank lines and spaces are allowed"
        );
    }
}
