//! Charts 1 and 2 (the paper's Figures 7 and 8): runtime, or CPU time, against chunks, one
//! line per core count, chunks on a logarithmic axis; with `mark_min`, each line's lowest
//! point gets a large cross.

use std::path::Path;

use plotters::prelude::*;

use super::{
    Area, DrawResult, LegendEntry, Mark, axis_styles, color, draw_line, log_keys,
    oversubscribed_entry, tick_label, x_extent, y_max,
};
use crate::report::series::Line;

/// Draws `lines` (x: chunks, y: seconds) into `path`.
pub fn draw(
    path: &Path,
    title: &str,
    subtitle: &str,
    y_desc: &str,
    lines: &[Line],
    mark_min: bool,
) -> anyhow::Result<()> {
    let mut legend: Vec<LegendEntry> = lines
        .iter()
        .enumerate()
        .map(|(i, l)| LegendEntry::new(l.label.clone(), Mark::Line(color(i))))
        .collect();
    if mark_min {
        legend.push(LegendEntry::new(
            "lowest point of a line",
            Mark::Cross(BLACK),
        ));
        legend.push(LegendEntry::new(
            "bars: 95 % confidence\ninterval of the mean",
            Mark::Line(BLACK),
        ));
    }
    legend.extend(oversubscribed_entry(lines));
    super::render(path, title, subtitle, &legend, |area| {
        plot(area, y_desc, lines, mark_min)
    })
}

fn plot(area: &Area<'_>, y_desc: &str, lines: &[Line], mark_min: bool) -> DrawResult {
    let (lo, hi) = x_extent(lines);
    let (x0, x1) = (lo / 1.3, hi * 1.3);
    let y1 = y_max(lines) * 1.08;
    let mut chart = ChartBuilder::on(area)
        .margin(16)
        .x_label_area_size(52)
        .y_label_area_size(76)
        .build_cartesian_2d(
            (x0..x1).log_scale().with_key_points(log_keys(lines)),
            0f64..y1,
        )?;
    let (labels, descs) = axis_styles();
    chart
        .configure_mesh()
        .x_desc("chunks per pass (log scale)")
        .y_desc(y_desc)
        .label_style(labels)
        .axis_desc_style(descs)
        .x_label_formatter(&|v| format!("{}", v.round()))
        .y_label_formatter(&tick_label)
        .light_line_style(RGBColor(240, 240, 240))
        .draw()?;
    for (i, line) in lines.iter().enumerate() {
        let c = color(i);
        // Chart 1 (runtime) shows each point's 95 % interval of the mean.
        draw_line(&mut chart, line, c, mark_min)?;
        if mark_min && let Some(m) = line.min_index() {
            let p = line.points[m];
            chart.draw_series(std::iter::once(Cross::new(
                (p.x, p.y),
                9,
                c.stroke_width(3),
            )))?;
        }
    }
    Ok(())
}
