//! Chart 3 (the paper's Figures 9 and 10): one strategy's best runtime against cores (above,
//! with the ideal `T_seq / p`) and its best speedup against cores (below, with the ideal
//! `S = p` and, where comparable, the paper's published speedups as a reference series); one
//! line per placement the strategy was measured at, in its colour, dashed or dotted when
//! pinned.

use std::path::Path;

use plotters::prelude::*;

use super::{
    Area, DrawResult, LegendEntry, Mark, cores_panel, cores_range, draw_dashed, draw_line,
    oversubscribed_entry, series_entry, series_mark, strategy_color, y_max,
};
use crate::report::paper;
use crate::report::series::Line;

/// What chart 3 shows.
#[derive(Debug, Clone)]
pub struct BestChart<'a> {
    /// The strategy.
    pub strategy: &'a str,
    /// Best runtime against cores, one line per placement.
    pub runtime: Vec<Line>,
    /// Best speedup against cores, the same lines in the same order.
    pub speedup: Vec<Line>,
    /// The group's `seq` mean, seconds.
    pub seq_s: f64,
    /// Whether to show the paper's speedups.
    pub paper: bool,
}

/// Draws `chart` into `path`.
pub fn draw(path: &Path, title: &str, subtitle: &str, chart: &BestChart<'_>) -> anyhow::Result<()> {
    let c = strategy_color(chart.strategy);
    let mut legend = match chart.runtime.as_slice() {
        [one] => vec![LegendEntry::new(
            format!("{} (best chunks;\nbars: 95 % CI)", one.label),
            series_mark(one, c),
        )],
        several => {
            let mut v: Vec<LegendEntry> = several.iter().map(series_entry).collect();
            v.push(LegendEntry::new(
                "best chunks per point;\nbars: 95 % CI",
                Mark::Line(BLACK),
            ));
            v
        }
    };
    legend.push(LegendEntry::new(
        "ideal: T_seq / p, S = p",
        Mark::Dashed(RGBColor(90, 90, 90)),
    ));
    if chart.paper {
        legend.push(LegendEntry::new(
            format!(
                "paper's speedups (Haskell,\n{},\nN = {}, {} steps)",
                paper::MACHINE,
                paper::N,
                paper::STEPS
            ),
            Mark::Triangle(RGBColor(110, 110, 110)),
        ));
    }
    legend.extend(oversubscribed_entry(&chart.runtime));
    super::render(path, title, subtitle, &legend, |area| plot(area, chart, c))
}

fn plot(area: &Area<'_>, chart: &BestChart<'_>, c: RGBColor) -> DrawResult {
    let (top, bottom) = area.split_vertically(area.dim_in_pixel().1 / 2);
    let grey = RGBColor(90, 90, 90);

    // The axis spans the measured cores only; the paper's speedups are drawn where they
    // inform, at those core counts.
    let (x0, x1) = cores_range(&chart.speedup);
    let measured = |cores: usize| {
        chart
            .speedup
            .iter()
            .any(|l| l.points.iter().any(|p| p.x == cores as f64))
    };
    let paper_points: Vec<(f64, f64)> = paper::TABLE
        .iter()
        .filter(|r| chart.paper && measured(r.cores))
        .map(|r| (r.cores as f64, r.speedup))
        .collect();
    let mut lines = chart.speedup.clone();
    lines.push(Line::new(
        String::new(),
        paper_points
            .iter()
            .map(|&(x, y)| crate::report::series::Point::exact(x, y))
            .collect(),
    ));
    let (x0, x1) = (x0.min(0.6), x1);

    // Runtime.
    let y1 = y_max(&chart.runtime).max(chart.seq_s) * 1.1;
    let mut ch = cores_panel(&top, (x0, x1), 0f64..y1, 76, "best runtime (s)")?;
    let mut cores: Vec<f64> = chart
        .runtime
        .iter()
        .flat_map(|l| l.points.iter().map(|p| p.x))
        .collect();
    cores.sort_by(f64::total_cmp);
    cores.dedup();
    let ideal: Vec<(f64, f64)> = cores.iter().map(|&x| (x, chart.seq_s / x)).collect();
    draw_dashed(&mut ch, ideal, grey)?;
    for line in &chart.runtime {
        draw_line(&mut ch, line, c, true)?;
    }

    // Speedup.
    let s1 = (y_max(&lines).max(x1 - 0.4)) * 1.1;
    let mut ch = cores_panel(&bottom, (x0, x1), 0f64..s1, 76, "best speedup (×)")?;
    draw_dashed(&mut ch, vec![(1.0, 1.0), (x1 - 0.4, x1 - 0.4)], grey)?;
    if !paper_points.is_empty() {
        ch.draw_series(LineSeries::new(
            paper_points.clone(),
            RGBColor(170, 170, 170).stroke_width(1),
        ))?;
        ch.draw_series(
            paper_points
                .into_iter()
                .map(|p| TriangleMarker::new(p, 7, RGBColor(110, 110, 110).filled())),
        )?;
    }
    for line in &chart.speedup {
        draw_line(&mut ch, line, c, true)?;
    }
    Ok(())
}
