//! `validation.png`: two panels side by side, the surge front Z against T and the column
//! height H against τ; the experiment as markers, the simulation as lines (the front also
//! shifted right by [`FRONT_SHIFT`], as the position verdict compares it). The chart is
//! planned as data first ([`plan`]), then drawn ([`write_png`]) in the bundled font.

use std::io::Write;

use anyhow::Context;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::font;
use sph_harness::validate::data::{Experiment, Point};
use sph_harness::validate::verdict::FRONT_SHIFT;

/// Width of the chart, pixels.
pub const WIDTH: u32 = 1200;
/// Height of the chart, pixels.
pub const HEIGHT: u32 = 560;
/// Height of the title band, pixels.
const TITLE_PX: u32 = 56;

const EXPERIMENT: RGBColor = RGBColor(0, 0, 0);
const SIMULATION: RGBColor = RGBColor(31, 119, 180);
const SHIFTED: RGBColor = RGBColor(255, 127, 14);

/// A simulated line.
#[derive(Debug, Clone, PartialEq)]
pub struct Line {
    /// Legend text.
    pub label: String,
    /// (x, y) in plot units.
    pub points: Vec<(f64, f64)>,
    /// Colour.
    pub color: RGBColor,
    /// Dashed rather than solid.
    pub dashed: bool,
}

/// One panel.
#[derive(Debug, Clone, PartialEq)]
pub struct Panel {
    /// Caption above the plot.
    pub caption: String,
    /// x axis description.
    pub x_desc: String,
    /// y axis description.
    pub y_desc: String,
    /// x range.
    pub x: (f64, f64),
    /// y range.
    pub y: (f64, f64),
    /// The experiment's points within the ranges.
    pub experiment: Vec<(f64, f64)>,
    /// The simulation's lines.
    pub lines: Vec<Line>,
    /// Where the legend goes (away from the data).
    pub legend_upper_left: bool,
}

/// The whole chart.
#[derive(Debug, Clone, PartialEq)]
pub struct Chart {
    /// Title.
    pub title: String,
    /// Subtitle.
    pub subtitle: String,
    /// Front, then column.
    pub panels: [Panel; 2],
}

/// The chart of a run at resolution `resolution` whose front is Z(T) (`front`) and column
/// H(τ) (`column`), against `experiment`.
pub fn plan(
    experiment: &Experiment,
    front: &[Point],
    column: &[Point],
    resolution: usize,
) -> Chart {
    let pairs = |c: &[Point]| c.iter().map(|p| (p.time, p.value)).collect::<Vec<_>>();
    let last = |c: &[Point]| c.last().map_or(0.0, |p| p.time);
    let within = |c: &[Point], x: f64, y: f64| {
        c.iter()
            .filter(|p| p.time <= x && p.value <= y)
            .map(|p| (p.time, p.value))
            .collect::<Vec<_>>()
    };
    let front_x = 3.6f64.max(last(front) + FRONT_SHIFT);
    let top = front.iter().map(|p| p.value).fold(0.0, f64::max);
    let front_y = 4.5f64.max((top * 1.05 * 2.0).ceil() / 2.0);
    let shifted = front
        .iter()
        .map(|p| (p.time + FRONT_SHIFT, p.value))
        .collect();
    let column_x = (last(column) + 1.0).ceil();
    Chart {
        title: format!(
            "wcsph dam break against Martin & Moyce (1952), square column n\u{b2} = 2, R = {resolution}"
        ),
        subtitle: format!(
            "markers: experiment; lines: simulation (the front also shifted right by \
             \u{394}T = {FRONT_SHIFT}, as the position verdict compares it)"
        ),
        panels: [
            Panel {
                caption: "surge front".to_owned(),
                x_desc: "T = t \u{221a}(2g/a)".to_owned(),
                y_desc: "Z = x_front / a".to_owned(),
                x: (0.0, front_x),
                y: (0.0, front_y),
                experiment: within(&experiment.surge_front, front_x, front_y),
                lines: vec![
                    Line {
                        label: "simulation".to_owned(),
                        points: pairs(front),
                        color: SIMULATION,
                        dashed: false,
                    },
                    Line {
                        label: format!("simulation, T + {FRONT_SHIFT}"),
                        points: shifted,
                        color: SHIFTED,
                        dashed: true,
                    },
                ],
                legend_upper_left: true,
            },
            Panel {
                caption: "column height at the wall".to_owned(),
                x_desc: "\u{3c4} = t \u{221a}(g/a)".to_owned(),
                y_desc: "H = h / 2a".to_owned(),
                x: (0.0, column_x),
                y: (0.0, 1.05),
                experiment: within(&experiment.column_height, column_x, 1.05),
                lines: vec![Line {
                    label: "simulation".to_owned(),
                    points: pairs(column),
                    color: SIMULATION,
                    dashed: false,
                }],
                legend_upper_left: false,
            },
        ],
    }
}

type DrawResult = Result<(), Box<dyn std::error::Error>>;
type Area<'a> = DrawingArea<BitMapBackend<'a>, Shift>;

/// Draws `chart` as a PNG of [`WIDTH`] × [`HEIGHT`] pixels into `out`.
pub fn write_png(chart: &Chart, mut out: impl Write) -> anyhow::Result<()> {
    font::ensure_registered()?;
    let mut pixels = vec![0u8; WIDTH as usize * HEIGHT as usize * 3];
    draw(&mut pixels, chart).map_err(|e| anyhow::anyhow!("cannot draw the chart: {e}"))?;
    let mut encoder = png::Encoder::new(&mut out, WIDTH, HEIGHT);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    let mut writer = encoder.write_header().context("cannot write the chart")?;
    writer
        .write_image_data(&pixels)
        .context("cannot write the chart")?;
    writer.finish().context("cannot write the chart")?;
    Ok(())
}

fn draw(pixels: &mut [u8], chart: &Chart) -> DrawResult {
    let root = BitMapBackend::with_buffer(pixels, (WIDTH, HEIGHT)).into_drawing_area();
    root.fill(&WHITE)?;
    let (head, body) = root.split_vertically(TITLE_PX);
    let centre = (WIDTH / 2) as i32;
    let style = TextStyle::from((font::FAMILY, 20).into_font().style(FontStyle::Bold))
        .pos(Pos::new(HPos::Center, VPos::Top));
    head.draw_text(&chart.title, &style, (centre, 6))?;
    let style = TextStyle::from((font::FAMILY, 14).into_font())
        .color(&RGBColor(80, 80, 80))
        .pos(Pos::new(HPos::Center, VPos::Top));
    head.draw_text(&chart.subtitle, &style, (centre, 33))?;
    let (left, right) = body.split_horizontally(WIDTH / 2);
    draw_panel(&left, &chart.panels[0])?;
    draw_panel(&right, &chart.panels[1])?;
    root.present()?;
    Ok(())
}

fn draw_panel(area: &Area<'_>, panel: &Panel) -> DrawResult {
    let mut ch = ChartBuilder::on(area)
        .caption(&panel.caption, (font::FAMILY, 17))
        .margin(14)
        .x_label_area_size(46)
        .y_label_area_size(56)
        .build_cartesian_2d(panel.x.0..panel.x.1, panel.y.0..panel.y.1)?;
    ch.configure_mesh()
        .x_desc(panel.x_desc.as_str())
        .y_desc(panel.y_desc.as_str())
        .label_style((font::FAMILY, 14))
        .axis_desc_style((font::FAMILY, 16))
        .light_line_style(RGBColor(240, 240, 240))
        .draw()?;
    for line in &panel.lines {
        let style = line.color.stroke_width(2);
        let c = line.color;
        let legend = move |(x, y): (i32, i32)| {
            PathElement::new(vec![(x, y), (x + 20, y)], c.stroke_width(2))
        };
        if line.dashed {
            ch.draw_series(DashedLineSeries::new(line.points.clone(), 8, 6, style))?
                .label(line.label.as_str())
                .legend(legend);
        } else {
            ch.draw_series(LineSeries::new(line.points.clone(), style))?
                .label(line.label.as_str())
                .legend(legend);
        }
    }
    ch.draw_series(
        panel
            .experiment
            .iter()
            .map(|&p| Circle::new(p, 5, EXPERIMENT.stroke_width(2))),
    )?
    .label("Martin & Moyce (1952)")
    .legend(|(x, y)| Circle::new((x + 10, y), 5, EXPERIMENT.stroke_width(2)));
    let position = if panel.legend_upper_left {
        SeriesLabelPosition::UpperLeft
    } else {
        SeriesLabelPosition::UpperRight
    };
    ch.configure_series_labels()
        .position(position)
        .label_font((font::FAMILY, 14))
        .background_style(WHITE.mix(0.9))
        .border_style(RGBColor(180, 180, 180))
        .draw()?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use sph_harness::output::sniff::PNG_SIGNATURE;
    use sph_harness::validate::verdict::pts;

    #[test]
    fn the_plan_keeps_the_experiment_inside_the_axes_and_shifts_the_front() {
        let e = sph_harness::validate::data::experiment().unwrap();
        let front = pts(&[(0.0, 1.0), (3.4, 4.4)]);
        let column = pts(&[(0.0, 1.0), (2.4, 0.4)]);
        let c = plan(&e, &front, &column, 20);
        assert!(c.title.contains("R = 20"));
        let [f, h] = &c.panels;
        assert_eq!(f.experiment.len(), 15);
        assert_eq!(
            f.lines[1].points,
            [(FRONT_SHIFT, 1.0), (3.4 + FRONT_SHIFT, 4.4)]
        );
        // τ up to 4: the points at 4.2, 5.25 and 7.4 are off the axis.
        assert_eq!(h.x, (0.0, 4.0));
        assert_eq!(h.experiment.len(), 14);
    }

    #[test]
    fn the_chart_is_a_png_of_its_size() {
        let e = sph_harness::validate::data::experiment().unwrap();
        let front = pts(&[(0.0, 1.0), (3.4, 4.4)]);
        let column = pts(&[(0.0, 1.0), (2.4, 0.4)]);
        let mut out = Vec::new();
        write_png(&plan(&e, &front, &column, 20), &mut out).unwrap();
        assert_eq!(out[..8], PNG_SIGNATURE);
        assert_eq!(
            out[16..24],
            [WIDTH.to_be_bytes(), HEIGHT.to_be_bytes()].concat()
        );
    }
}
