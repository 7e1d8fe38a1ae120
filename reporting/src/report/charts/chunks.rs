//! Charts 1 and 2 (the paper's Figures 7 and 8): runtime, or CPU time, against chunks, one
//! line per core count, chunks on a logarithmic axis; with `mark_min`, each line's lowest
//! point gets a large cross. A line's trials ([`Line::dots`]) are drawn as small dots just
//! right of their mean, so the spread behind each point shows.

use std::path::Path;

use plotters::prelude::*;

use super::{
    Area, DrawResult, LegendEntry, Mark, TRIAL_DOT, axis_styles, color, draw_line, log_keys,
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
    if lines.iter().any(|l| !l.dots.is_empty()) {
        legend.push(LegendEntry::new("each trial", Mark::Dot(BLACK)));
    }
    legend.extend(oversubscribed_entry(lines));
    super::render(path, title, subtitle, &legend, |area| {
        plot(area, y_desc, lines, mark_min)
    })
}

/// How far right of its mean a trial's dot is drawn: a factor on the log chunks axis.
const DOT_SHIFT: f64 = 1.06;

fn plot(area: &Area<'_>, y_desc: &str, lines: &[Line], mark_min: bool) -> DrawResult {
    let (lo, hi) = x_extent(lines);
    let (x0, x1) = (lo / 1.3, hi * 1.3);
    let dots = lines.iter().flat_map(|l| l.dots.iter().map(|d| d.1));
    let y1 = dots.fold(y_max(lines), f64::max) * 1.08;
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
        // Beside the mean: a little to the right on the log axis, clear of its bar.
        chart.draw_series(
            line.dots
                .iter()
                .map(|&(x, y)| Circle::new((x * DOT_SHIFT, y), TRIAL_DOT, c.filled())),
        )?;
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::report::series::Point;

    /// The RGB pixels of the PNG at `path`.
    fn pixels(path: &Path) -> Vec<[u8; 3]> {
        let file = std::io::BufReader::new(std::fs::File::open(path).unwrap());
        let mut reader = png::Decoder::new(file).read_info().unwrap();
        let mut buf = vec![0; reader.output_buffer_size().unwrap()];
        let info = reader.next_frame(&mut buf).unwrap();
        buf[..info.buffer_size()]
            .chunks(3)
            .map(|p| [p[0], p[1], p[2]])
            .collect()
    }

    #[test]
    fn each_trial_is_drawn_as_a_dot_beside_its_mean() {
        let dir = tempfile::tempdir().unwrap();
        let point = |x, y: f64| Point {
            lo: y - 0.1,
            hi: y + 0.1,
            ..Point::exact(x, y)
        };
        let mut line = Line::new("1 core", vec![point(2.0, 1.0), point(8.0, 0.6)]);
        let (bare, dotted) = (dir.path().join("bare.png"), dir.path().join("dots.png"));
        draw(&bare, "t", "s", "y", std::slice::from_ref(&line), true).unwrap();
        // Trials within the bars, so that the axes stay the same.
        line.dots = vec![(2.0, 0.95), (2.0, 1.05), (8.0, 0.55), (8.0, 0.65)];
        draw(&dotted, "t", "s", "y", std::slice::from_ref(&line), true).unwrap();
        let c = color(0);
        let c = [c.0, c.1, c.2];
        let added = pixels(&bare)
            .iter()
            .zip(pixels(&dotted))
            .filter(|(b, d)| **b != c && *d == c)
            .count();
        // Four dots of radius 2 (about 13 pixels each) that the bare chart lacks.
        assert!(added >= 4 * 9, "{added} pixels added");
    }
}
