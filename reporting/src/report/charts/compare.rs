//! The comparison chart: one strategy's best speedup (above, with the ideal `S = p`) and
//! efficiency `S / p` (below, with the ideal 1) against cores, one line per machine, bars the
//! 95 % interval of each cores value's best cell.
//!
//! Charts 4 and 5 colour a line by its strategy; here every line is the same strategy and the
//! colour names the machine (the side's index), so the lines are drawn with the shared panel
//! and line helpers rather than through those charts.

use std::path::Path;

use plotters::prelude::*;

use super::{
    Area, DrawResult, LegendEntry, Mark, color, cores_panel, cores_range, draw_dashed, draw_line,
    oversubscribed_entry, y_max,
};
use crate::report::series::Line;

/// One machine's lines in a comparison chart.
#[derive(Debug, Clone, PartialEq)]
pub struct MachineLines {
    /// The side's index: its colour.
    pub side: usize,
    /// The legend text (may hold `\n`).
    pub legend: String,
    /// Best speedup against cores.
    pub speedup: Line,
    /// Efficiency against cores.
    pub efficiency: Line,
}

/// Draws `machines` into `path`.
pub fn draw(
    path: &Path,
    title: &str,
    subtitle: &str,
    machines: &[MachineLines],
) -> anyhow::Result<()> {
    let mut legend: Vec<LegendEntry> = machines
        .iter()
        .map(|m| LegendEntry::new(m.legend.clone(), Mark::Line(color(m.side))))
        .collect();
    legend.push(LegendEntry::new(
        "ideal: S = p,\nefficiency 1",
        Mark::Dashed(RGBColor(90, 90, 90)),
    ));
    legend.push(LegendEntry::new(
        "bars: 95 % confidence\ninterval of the best cell",
        Mark::Line(BLACK),
    ));
    let speedups: Vec<Line> = machines.iter().map(|m| m.speedup.clone()).collect();
    legend.extend(oversubscribed_entry(&speedups));
    super::render(path, title, subtitle, &legend, |area| plot(area, machines))
}

fn plot(area: &Area<'_>, machines: &[MachineLines]) -> DrawResult {
    let (top, bottom) = area.split_vertically(area.dim_in_pixel().1 / 2);
    let grey = RGBColor(90, 90, 90);
    let speedups: Vec<Line> = machines.iter().map(|m| m.speedup.clone()).collect();
    let efficiencies: Vec<Line> = machines.iter().map(|m| m.efficiency.clone()).collect();
    let (x0, x1) = cores_range(&speedups);
    let (first, last) = (x0 + 0.4, x1 - 0.4);

    let y1 = y_max(&speedups).max(last) * 1.1;
    let mut ch = cores_panel(&top, (x0, x1), 0f64..y1, 70, "best speedup (×)")?;
    draw_dashed(&mut ch, vec![(first, first), (last, last)], grey)?;
    for m in machines {
        draw_line(&mut ch, &m.speedup, color(m.side), true)?;
    }

    let y1 = y_max(&efficiencies).max(1.0) * 1.1;
    let mut ch = cores_panel(&bottom, (x0, x1), 0f64..y1, 70, "efficiency S / p")?;
    draw_dashed(&mut ch, vec![(x0, 1.0), (x1, 1.0)], grey)?;
    for m in machines {
        draw_line(&mut ch, &m.efficiency, color(m.side), true)?;
    }
    Ok(())
}
