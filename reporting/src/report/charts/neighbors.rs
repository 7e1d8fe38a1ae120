//! Chart 6: all-pairs against grid: seconds per step against N (both axes logarithmic), for
//! `seq` and for the fastest parallel cell of each neighbour search.

use std::path::Path;

use plotters::prelude::*;

use super::{
    Area, DrawResult, LegendEntry, Mark, axis_styles, color, draw_line, log_keys,
    oversubscribed_entry, sig_label, x_extent,
};
use crate::report::series::Line;

/// Draws `lines` into `path`.
pub fn draw(path: &Path, title: &str, subtitle: &str, lines: &[Line]) -> anyhow::Result<()> {
    let mut legend: Vec<LegendEntry> = lines
        .iter()
        .enumerate()
        .map(|(i, l)| LegendEntry::new(l.label.replace(", ", ",\n"), Mark::Line(color(i))))
        .collect();
    legend.extend(oversubscribed_entry(lines));
    super::render(path, title, subtitle, &legend, |area| plot(area, lines))
}

fn plot(area: &Area<'_>, lines: &[Line]) -> DrawResult {
    let (lo, hi) = x_extent(lines);
    let ys = lines
        .iter()
        .flat_map(|l| l.points.iter().flat_map(|p| [p.lo, p.hi, p.y]));
    let ylo = ys.clone().fold(f64::INFINITY, f64::min).max(1e-12);
    let yhi = ys.fold(0f64, f64::max).max(ylo * 10.0);
    let mut chart = ChartBuilder::on(area)
        .margin(16)
        .x_label_area_size(52)
        .y_label_area_size(84)
        .build_cartesian_2d(
            (lo / 1.5..hi * 1.5)
                .log_scale()
                .with_key_points(log_keys(lines)),
            (ylo / 2.0..yhi * 2.0).log_scale(),
        )?;
    let (labels, descs) = axis_styles();
    chart
        .configure_mesh()
        .x_desc("particles N (log scale)")
        .y_desc("seconds per step (log scale)")
        .label_style(labels)
        .axis_desc_style(descs)
        .x_label_formatter(&|v| format!("{}", v.round()))
        .y_label_formatter(&sig_label)
        .light_line_style(RGBColor(240, 240, 240))
        .draw()?;
    for (i, line) in lines.iter().enumerate() {
        draw_line(&mut chart, line, color(i), true)?;
    }
    Ok(())
}
