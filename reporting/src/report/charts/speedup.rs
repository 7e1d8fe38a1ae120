//! Chart 4: every strategy's best speedup against cores, error bars the 95 % interval of the
//! best cell's speedup, paired by round, with the ideal `S = p`; one line per strategy and
//! placement, and the core counts on SMT siblings shaded.

use std::path::Path;

use plotters::prelude::*;

use super::{
    Area, CoresAxis, DrawResult, LegendEntry, Mark, axis_styles, cores_range, draw_dashed,
    draw_line, draw_smt_band, integer_label, line_color, oversubscribed_entry, series_entry,
    smt_entry, tick_label, y_max,
};
use crate::report::series::{Line, SmtBand};

/// Draws `lines` (one per strategy and placement) into `path`, `smt` shaded.
pub fn draw(
    path: &Path,
    title: &str,
    subtitle: &str,
    lines: &[Line],
    smt: Option<&SmtBand>,
) -> anyhow::Result<()> {
    let mut legend: Vec<LegendEntry> = lines.iter().map(series_entry).collect();
    legend.push(LegendEntry::new(
        "ideal: S = p",
        Mark::Dashed(RGBColor(90, 90, 90)),
    ));
    legend.push(LegendEntry::new(
        "bars: 95 % confidence\ninterval of the speedup",
        Mark::Line(BLACK),
    ));
    legend.extend(oversubscribed_entry(lines));
    legend.extend(smt_entry(smt));
    super::render(path, title, subtitle, &legend, |area| {
        plot(area, lines, smt)
    })
}

fn plot(area: &Area<'_>, lines: &[Line], smt: Option<&SmtBand>) -> DrawResult {
    let (x0, x1) = cores_range(lines);
    let y1 = y_max(lines).max(x1 - 0.4) * 1.08;
    let mut chart = ChartBuilder::on(area)
        .margin(16)
        .x_label_area_size(52)
        .y_label_area_size(70)
        .build_cartesian_2d(CoresAxis::new(x0, x1), 0f64..y1)?;
    let (labels, descs) = axis_styles();
    chart
        .configure_mesh()
        .disable_x_mesh()
        .x_label_formatter(&integer_label)
        .y_label_formatter(&tick_label)
        .x_desc("cores")
        .y_desc("speedup over seq (×)")
        .label_style(labels)
        .axis_desc_style(descs)
        .draw()?;
    if let Some(band) = smt {
        draw_smt_band(&mut chart, band, (x0, x1), (0.0, y1))?;
    }
    draw_dashed(
        &mut chart,
        vec![(x0 + 0.4, x0 + 0.4), (x1 - 0.4, x1 - 0.4)],
        RGBColor(90, 90, 90),
    )?;
    for line in lines {
        draw_line(&mut chart, line, line_color(line), true)?;
    }
    Ok(())
}
