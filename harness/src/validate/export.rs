//! The validation's CSV files.
//!
//! - `surge_front.csv`: `t_s,T,Z`, one row per sample;
//! - `column_height.csv`: `t_s,tau,H`, one row per sample;
//! - `validation.png`: the chart (`sph_report::plot::validation`).
//!
//! Numbers are written in the shortest form that parses back to the same bits.

use std::io::Write;

use anyhow::Context;
use serde::Serialize;

use super::probe::{Sample, Scales};

/// The front's samples.
pub const SURGE_FRONT_CSV: &str = "surge_front.csv";
/// The column's samples.
pub const COLUMN_HEIGHT_CSV: &str = "column_height.csv";
/// The chart.
pub const VALIDATION_PNG: &str = "validation.png";
/// `surge_front.csv`'s header.
pub const SURGE_FRONT_HEADER: &str = "t_s,T,Z";
/// `column_height.csv`'s header.
pub const COLUMN_HEIGHT_HEADER: &str = "t_s,tau,H";

#[derive(Serialize)]
struct FrontRow {
    t_s: f64,
    #[serde(rename = "T")]
    front_time: f64,
    #[serde(rename = "Z")]
    front: f64,
}

#[derive(Serialize)]
struct ColumnRow {
    t_s: f64,
    tau: f64,
    #[serde(rename = "H")]
    height: f64,
}

/// Writes `surge_front.csv`: per sample, t (s), T = t √(2g/a) and Z = x_front / a.
pub fn write_surge_front(
    samples: &[Sample],
    scales: &Scales,
    out: impl Write,
) -> anyhow::Result<()> {
    let rows = samples.iter().map(|s| FrontRow {
        t_s: s.t_s,
        front_time: scales.front_time(s.t_s),
        front: s.front_m / scales.a,
    });
    write_rows(rows, out).context("cannot write the surge front")
}

/// Writes `column_height.csv`: per sample, t (s), τ = t √(g/a) and H = h / (2a).
pub fn write_column_height(
    samples: &[Sample],
    scales: &Scales,
    out: impl Write,
) -> anyhow::Result<()> {
    let rows = samples.iter().map(|s| ColumnRow {
        t_s: s.t_s,
        tau: scales.column_time(s.t_s),
        height: s.column_m / (2.0 * scales.a),
    });
    write_rows(rows, out).context("cannot write the column height")
}

/// Writes `rows` as CSV with a header from their field names.
fn write_rows(rows: impl Iterator<Item = impl Serialize>, out: impl Write) -> csv::Result<()> {
    let mut w = csv::Writer::from_writer(out);
    for row in rows {
        w.serialize(row)?;
    }
    w.flush().map_err(csv::Error::from)
}

#[cfg(test)]
mod tests {
    use super::*;

    const SCALES: Scales = Scales {
        a: 1.0,
        g: 2.0,
        dx: 0.1,
    };

    fn samples() -> Vec<Sample> {
        vec![
            Sample {
                t_s: 0.0,
                front_m: 0.95,
                column_m: 1.95,
            },
            Sample {
                t_s: 0.25,
                front_m: 1.5,
                column_m: 1.0,
            },
        ]
    }

    #[test]
    fn the_surge_front_is_t_s_t_and_z() {
        let mut out = Vec::new();
        write_surge_front(&samples(), &SCALES, &mut out).unwrap();
        // T = t √(2g/a) = 2t.
        assert_eq!(
            String::from_utf8(out).unwrap(),
            "t_s,T,Z\n0.0,0.0,0.95\n0.25,0.5,1.5\n"
        );
    }

    #[test]
    fn the_column_height_is_t_s_tau_and_h() {
        let mut out = Vec::new();
        write_column_height(&samples(), &SCALES, &mut out).unwrap();
        // τ = t √(g/a) = t √2, H = h / 2.
        let tau = 0.25 * 2f64.sqrt();
        assert_eq!(
            String::from_utf8(out).unwrap(),
            format!("t_s,tau,H\n0.0,0.0,0.975\n0.25,{tau},0.5\n")
        );
    }
}
