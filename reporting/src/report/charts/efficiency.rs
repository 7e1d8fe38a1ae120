//! Chart 5: parallel efficiency `S / p` (above) and the Karp–Flatt serial fraction
//! `e = (1/S − 1/p) / (1 − 1/p)` with its 95 % interval as bars (below, only where S > 1 and
//! the interval lies above 0: [`crate::report::cell::Best::serial_fraction`]) against cores,
//! one line per strategy and placement; the serial-fraction axis is clipped to [0, 1] and
//! says when it clips. Core counts on SMT siblings are shaded in both panels.

use std::path::Path;

use plotters::prelude::*;

use super::{
    Area, DrawResult, LegendEntry, Mark, cores_panel, cores_range, draw_dashed, draw_line,
    draw_smt_band, line_color, oversubscribed_entry, series_entry, smt_entry, y_max,
};
use crate::report::series::{Line, SmtBand};

/// Draws efficiency and serial-fraction lines into `path`, `smt` shaded.
pub fn draw(
    path: &Path,
    title: &str,
    subtitle: &str,
    (efficiency, serial): (&[Line], &[Line]),
    smt: Option<&SmtBand>,
) -> anyhow::Result<()> {
    let mut legend: Vec<LegendEntry> = efficiency.iter().map(series_entry).collect();
    legend.push(LegendEntry::new(
        "ideal: efficiency 1,\nserial fraction 0",
        Mark::Dashed(RGBColor(90, 90, 90)),
    ));
    legend.extend(oversubscribed_entry(efficiency));
    legend.extend(smt_entry(smt));
    super::render(path, title, subtitle, &legend, |area| {
        plot(area, efficiency, serial, smt)
    })
}

fn plot(
    area: &Area<'_>,
    efficiency: &[Line],
    serial: &[Line],
    smt: Option<&SmtBand>,
) -> DrawResult {
    let (top, bottom) = area.split_vertically(area.dim_in_pixel().1 / 2);
    let grey = RGBColor(90, 90, 90);
    let (x0, x1) = cores_range(efficiency);

    let y1 = y_max(efficiency).max(1.0) * 1.1;
    let mut ch = cores_panel(&top, (x0, x1), 0f64..y1, 70, "efficiency S / p")?;
    if let Some(band) = smt {
        draw_smt_band(&mut ch, band, (x0, x1), (0.0, y1))?;
    }
    draw_dashed(&mut ch, vec![(x0, 1.0), (x1, 1.0)], grey)?;
    for line in efficiency {
        draw_line(&mut ch, line, line_color(line), false)?;
    }

    // The axis is clipped to [SERIAL_MIN, 1] so one pathological strategy cannot stretch
    // it; a clipped point is drawn on the edge and the panel says so.
    let clipped: Vec<Line> = serial.iter().map(clip).collect();
    let any_clipped = clipped
        .iter()
        .zip(serial)
        .any(|(c, l)| c.points != l.points);
    let serial = &clipped[..];
    let ys = serial.iter().flat_map(|l| l.points.iter().map(|p| p.hi));
    let lo = ys.clone().fold(0f64, f64::min);
    let hi = ys.fold(0.1f64, f64::max);
    let pad = (hi - lo) * 0.1;
    let mut ch = cores_panel(
        &bottom,
        (x0, x1),
        (lo - pad)..(hi + pad),
        70,
        "serial fraction e",
    )?;
    if let Some(band) = smt {
        draw_smt_band(&mut ch, band, (x0, x1), (lo - pad, hi + pad))?;
    }
    draw_dashed(&mut ch, vec![(x0, 0.0), (x1, 0.0)], grey)?;
    for line in serial {
        draw_line(&mut ch, line, line_color(line), true)?;
    }
    if any_clipped {
        let style = TextStyle::from((crate::plot::font::FAMILY, 14).into_font())
            .color(&RGBColor(180, 0, 0));
        ch.draw_series(std::iter::once(Text::new(
            format!("values beyond [{SERIAL_MIN}, 1] clipped to the edge"),
            (x0 + 0.1, hi + pad * 0.5),
            style,
        )))?;
    }
    Ok(())
}

/// The lowest serial fraction the panel shows (only fractions whose interval lies above 0
/// are drawn).
const SERIAL_MIN: f64 = 0.0;

/// `line` with every value and interval end clipped to `[SERIAL_MIN, 1]`.
fn clip(line: &Line) -> Line {
    let mut out = line.clone();
    for p in &mut out.points {
        let clip = |v: f64| v.clamp(SERIAL_MIN, 1.0);
        (p.y, p.lo, p.hi) = (clip(p.y), clip(p.lo), clip(p.hi));
    }
    out
}
