//! The report's charts, one file per kind: they only draw series built by
//! [`super::series`]. Every chart is a PNG of [`WIDTH`] × [`HEIGHT`] pixels in the bundled
//! font, with its legend in a panel right of the plot so that it never covers data.
//! Oversubscribed points (more threads than the machine has) are hollow; the legend says so.
//! A strategy's lines keep its colour at every placement: solid unpinned, dashed pinned
//! `spread`, dotted pinned `compact` ([`Dash`]). Core counts that put threads on SMT
//! siblings are shaded ([`draw_smt_band`]).

pub mod best;
pub mod chunks;
pub mod compare;
pub mod efficiency;
pub mod neighbors;
pub mod speedup;

use std::path::Path;

use anyhow::Context;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::series::{Line, Point, SmtBand};
use crate::plot::font;
use sph_harness::topology::Pin;

/// Width of every chart, pixels.
pub const WIDTH: u32 = 1000;
/// Height of every chart, pixels.
pub const HEIGHT: u32 = 650;
/// Width of the legend panel on the right, pixels.
const LEGEND_PX: u32 = 250;
/// Height of the title band, pixels.
const TITLE_PX: u32 = 56;

/// What drawing functions return: plotters' errors are boxed, then given context.
pub(crate) type DrawResult = Result<(), Box<dyn std::error::Error>>;
/// A drawing area in pixels.
pub(crate) type Area<'a> = DrawingArea<BitMapBackend<'a>, Shift>;

/// A panel of the best-cell and efficiency charts: the cores across (integer labels), `y`
/// up, described as `y_desc`, its mesh drawn; `y_area` pixels for the y labels.
pub fn cores_panel<'a, 'b>(
    area: &'a Area<'b>,
    (x0, x1): (f64, f64),
    y: std::ops::Range<f64>,
    y_area: u32,
    y_desc: &str,
) -> Result<CoresPanel<'a, 'b>, Box<dyn std::error::Error>> {
    let (labels, descs) = axis_styles();
    let mut ch = ChartBuilder::on(area)
        .margin(12)
        .x_label_area_size(44)
        .y_label_area_size(y_area)
        .build_cartesian_2d(CoresAxis::new(x0, x1), y)?;
    ch.configure_mesh()
        .disable_x_mesh()
        .x_label_formatter(&integer_label)
        .y_label_formatter(&tick_label)
        .x_desc("cores")
        .y_desc(y_desc)
        .label_style(labels)
        .axis_desc_style(descs)
        .draw()?;
    Ok(ch)
}

/// What [`cores_panel`] builds.
pub type CoresPanel<'a, 'b> = ChartContext<
    'a,
    BitMapBackend<'b>,
    Cartesian2d<CoresAxis, plotters::coord::types::RangedCoordf64>,
>;

/// A colour per index, from the Tableau 10 palette (cycled).
pub fn color(i: usize) -> RGBColor {
    const PALETTE: [(u8, u8, u8); 10] = [
        (31, 119, 180),
        (255, 127, 14),
        (44, 160, 44),
        (214, 39, 40),
        (148, 103, 189),
        (140, 86, 75),
        (227, 119, 194),
        (127, 127, 127),
        (188, 189, 34),
        (23, 190, 207),
    ];
    let (r, g, b) = PALETTE[i % PALETTE.len()];
    // A second round (more than ten lines) in darker shades, so no two lines share a colour
    // below twenty.
    if (i / PALETTE.len()) % 2 == 1 {
        let dark = |v: u8| (f64::from(v) * 0.55) as u8;
        RGBColor(dark(r), dark(g), dark(b))
    } else {
        RGBColor(r, g, b)
    }
}

/// A strategy's colour: by its place in the registry, so it is the same in every chart.
pub fn strategy_color(name: &str) -> RGBColor {
    let i = sph_strategies::StrategyName::ALL
        .iter()
        .position(|s| s.as_str() == name)
        .unwrap_or(7);
    color(i)
}

/// A line's colour: its strategy's where it shows a series, else by its label (a strategy's
/// name, or anything else, grey).
pub fn line_color(line: &Line) -> RGBColor {
    match line.series {
        Some(key) => strategy_color(key.strategy.as_str()),
        None => strategy_color(&line.label),
    }
}

/// How a line's segments are drawn: by the placement of its series.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Dash {
    /// Unbroken (unpinned, and every line without a series).
    Solid,
    /// Long dashes (pinned `spread`).
    Dashed,
    /// Short dashes, dots at this width (pinned `compact`).
    Dotted,
}

impl Dash {
    /// The style of a series at placement `pin`.
    pub fn of(pin: Pin) -> Dash {
        match pin {
            Pin::None => Dash::Solid,
            Pin::Spread => Dash::Dashed,
            Pin::Compact => Dash::Dotted,
        }
    }

    /// How captions name it.
    pub fn as_str(self) -> &'static str {
        match self {
            Dash::Solid => "solid",
            Dash::Dashed => "dashed",
            Dash::Dotted => "dotted",
        }
    }

    /// (dash, gap) in pixels; `None` for solid.
    fn pattern(self) -> Option<(i32, i32)> {
        match self {
            Dash::Solid => None,
            Dash::Dashed => Some((9, 5)),
            Dash::Dotted => Some((3, 4)),
        }
    }
}

/// The legend entry of a line that shows a series: its label, in its colour and style.
pub fn series_entry(line: &Line) -> LegendEntry {
    LegendEntry::new(line.label.clone(), series_mark(line, line_color(line)))
}

/// The legend mark of `line` in colour `c`: a solid line with a dot, or the line's dashes.
pub fn series_mark(line: &Line, c: RGBColor) -> Mark {
    match Dash::of(line.pin()) {
        Dash::Solid => Mark::Line(c),
        dash => Mark::Styled(c, dash),
    }
}

/// The colour of the SMT band, laid over the plot translucent so that the grid shows
/// through.
pub const SMT_FILL: RGBColor = RGBColor(255, 170, 60);
/// The opacity of the SMT band.
const SMT_ALPHA: f64 = 0.22;

/// The legend entry of the SMT band, where there is one.
pub fn smt_entry(band: Option<&SmtBand>) -> Option<LegendEntry> {
    band.map(|_| {
        LegendEntry::new(
            "SMT siblings: more threads\nthan physical cores",
            Mark::Band(SMT_FILL),
        )
    })
}

/// Shades the core counts past the physical cores up to `band.to`, from half a core past
/// the physical cores to half a core past `band.to` (so that the shade holds exactly the
/// points on SMT siblings), clipped to the x range `x0..x1`, over the y range `y0..y1`,
/// behind whatever is drawn next.
pub fn draw_smt_band<Y>(
    chart: &mut ChartContext<'_, BitMapBackend<'_>, Cartesian2d<CoresAxis, Y>>,
    band: &SmtBand,
    (x0, x1): (f64, f64),
    (y0, y1): (f64, f64),
) -> DrawResult
where
    Y: Ranged<ValueType = f64>,
{
    let from = (band.physical_cores as f64 + 0.5).clamp(x0, x1);
    let to = (band.to as f64 + 0.5).clamp(x0, x1);
    if to > from {
        chart.draw_series(std::iter::once(Rectangle::new(
            [(from, y0), (to, y1)],
            SMT_FILL.mix(SMT_ALPHA).filled(),
        )))?;
    }
    Ok(())
}

/// How a legend entry is drawn.
#[derive(Debug, Clone, Copy)]
pub enum Mark {
    /// A solid line with a filled dot.
    Line(RGBColor),
    /// A dashed or dotted line with a filled dot (a pinned series).
    Styled(RGBColor, Dash),
    /// A translucent filled square (a shaded region).
    Band(RGBColor),
    /// A dashed line.
    Dashed(RGBColor),
    /// A hollow dot (oversubscribed).
    Hollow(RGBColor),
    /// A small dot (one trial).
    Dot(RGBColor),
    /// A red ring (contended: other work used the machine).
    Ring,
    /// A large cross (a line's minimum).
    Cross(RGBColor),
    /// A triangle (a reference series).
    Triangle(RGBColor),
}

/// A legend entry.
#[derive(Debug, Clone)]
pub struct LegendEntry {
    /// Text (may hold one `\n` for a second line).
    pub label: String,
    /// Symbol.
    pub mark: Mark,
}

impl LegendEntry {
    /// An entry.
    pub fn new(label: impl Into<String>, mark: Mark) -> LegendEntry {
        LegendEntry {
            label: label.into(),
            mark,
        }
    }
}

/// The radius of a trial's dot, pixels.
pub const TRIAL_DOT: i32 = 2;

/// The colour of the ring around a contended point.
pub const CONTENDED: RGBColor = RGBColor(220, 0, 0);

/// The standard "hollow = oversubscribed" and "ring = contended" entries, when any line has
/// such a point.
pub fn oversubscribed_entry(lines: &[Line]) -> Vec<LegendEntry> {
    let mut out = Vec::new();
    if lines.iter().any(Line::any_oversubscribed) {
        out.push(LegendEntry::new(
            "oversubscribed: more threads\nthan hardware threads",
            Mark::Hollow(BLACK),
        ));
    }
    if lines.iter().any(|l| l.points.iter().any(|p| p.contended)) {
        out.push(LegendEntry::new(
            "contended: other work\nused the machine",
            Mark::Ring,
        ));
    }
    out
}

/// Draws a chart into `path`: `draw` gets the plot area (below the title, left of the legend).
pub fn render(
    path: &Path,
    title: &str,
    subtitle: &str,
    legend: &[LegendEntry],
    draw: impl FnOnce(&Area<'_>) -> DrawResult,
) -> anyhow::Result<()> {
    font::ensure_registered()?;
    let mut pixels = vec![0u8; WIDTH as usize * HEIGHT as usize * 3];
    compose(&mut pixels, title, subtitle, legend, draw)
        .map_err(|e| anyhow::anyhow!("{e}"))
        .with_context(|| format!("cannot draw '{}'", path.display()))?;
    let mut file = sph_harness::output::atomic::AtomicFile::create(path)?;
    let mut encoder = png::Encoder::new(&mut file, WIDTH, HEIGHT);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    let mut writer = encoder
        .write_header()
        .with_context(|| format!("cannot write '{}'", path.display()))?;
    writer
        .write_image_data(&pixels)
        .with_context(|| format!("cannot write '{}'", path.display()))?;
    writer
        .finish()
        .with_context(|| format!("cannot write '{}'", path.display()))?;
    file.commit()
}

fn compose(
    pixels: &mut [u8],
    title: &str,
    subtitle: &str,
    legend: &[LegendEntry],
    draw: impl FnOnce(&Area<'_>) -> DrawResult,
) -> DrawResult {
    let root = BitMapBackend::with_buffer(pixels, (WIDTH, HEIGHT)).into_drawing_area();
    root.fill(&WHITE)?;
    let (head, body) = root.split_vertically(TITLE_PX);
    let centre = (WIDTH / 2) as i32;
    let style = TextStyle::from((font::FAMILY, 21).into_font().style(FontStyle::Bold))
        .pos(Pos::new(HPos::Center, VPos::Top));
    head.draw_text(title, &style, (centre, 6))?;
    let style = TextStyle::from((font::FAMILY, 15).into_font())
        .color(&RGBColor(80, 80, 80))
        .pos(Pos::new(HPos::Center, VPos::Top));
    head.draw_text(subtitle, &style, (centre, 33))?;
    let (plot, side) = body.split_horizontally(WIDTH - LEGEND_PX);
    draw(&plot)?;
    draw_legend(&side, legend)?;
    root.present()?;
    Ok(())
}

fn draw_legend(area: &Area<'_>, entries: &[LegendEntry]) -> DrawResult {
    let text =
        TextStyle::from((font::FAMILY, 14).into_font()).pos(Pos::new(HPos::Left, VPos::Center));
    // Rows of 18 px per text line; the gaps between entries shrink so that many entries
    // (e.g. 16 core counts) still fit the panel.
    let text_lines: i32 = entries
        .iter()
        .map(|e| e.label.split('\n').count() as i32)
        .sum();
    let free = area.dim_in_pixel().1 as i32 - 40 - 18 * text_lines;
    let gap = (free / (entries.len() as i32).max(1)).clamp(2, 14);
    let mut y = 40;
    for e in entries {
        let (x0, x1, cx) = (10, 44, 27);
        match e.mark {
            Mark::Line(c) => {
                area.draw(&PathElement::new(vec![(x0, y), (x1, y)], c.stroke_width(2)))?;
                area.draw(&Circle::new((cx, y), 4, c.filled()))?;
            }
            Mark::Dashed(c) => {
                for s in (x0..x1).step_by(10) {
                    area.draw(&PathElement::new(
                        vec![(s, y), ((s + 6).min(x1), y)],
                        c.stroke_width(2),
                    ))?;
                }
            }
            Mark::Styled(c, dash) => {
                let (on, off) = dash.pattern().unwrap_or((x1 - x0, 0));
                for s in (x0..x1).step_by((on + off) as usize) {
                    area.draw(&PathElement::new(
                        vec![(s, y), ((s + on).min(x1), y)],
                        c.stroke_width(2),
                    ))?;
                }
                area.draw(&Circle::new((cx, y), 4, c.filled()))?;
            }
            Mark::Band(c) => {
                area.draw(&Rectangle::new(
                    [(x0 + 6, y - 8), (x1 - 6, y + 8)],
                    c.mix(SMT_ALPHA).filled(),
                ))?;
            }
            Mark::Hollow(c) => area.draw(&Circle::new((cx, y), 5, c.stroke_width(2)))?,
            Mark::Dot(c) => area.draw(&Circle::new((cx, y), TRIAL_DOT, c.filled()))?,
            Mark::Ring => area.draw(&Circle::new((cx, y), 9, CONTENDED.stroke_width(2)))?,
            Mark::Cross(c) => area.draw(&Cross::new((cx, y), 7, c.stroke_width(3)))?,
            Mark::Triangle(c) => area.draw(&TriangleMarker::new((cx, y), 7, c.filled()))?,
        }
        let lines: Vec<&str> = e.label.split('\n').collect();
        for (i, l) in lines.iter().enumerate() {
            area.draw_text(l, &text, (x1 + 10, y + 18 * i as i32))?;
        }
        y += 18 * lines.len() as i32 + gap;
    }
    Ok(())
}

/// Formats a cores tick: whole numbers only (other ticks are left blank).
pub fn integer_label(v: &f64) -> String {
    if (v - v.round()).abs() < 1e-9 && *v >= 0.0 {
        format!("{}", v.round() as i64)
    } else {
        String::new()
    }
}

/// A number for a tick: no needless decimals.
pub fn tick_label(v: &f64) -> String {
    let a = v.abs();
    if a == 0.0 {
        "0".to_owned()
    } else if a >= 100.0 {
        format!("{v:.0}")
    } else if a >= 1.0 {
        let s = format!("{v:.2}");
        s.trim_end_matches('0').trim_end_matches('.').to_owned()
    } else {
        format!("{v:.3}")
            .trim_end_matches('0')
            .trim_end_matches('.')
            .to_owned()
    }
}

/// A number to three significant digits, without trailing zeros (for log axes).
pub fn sig_label(v: &f64) -> String {
    if !(v.is_finite() && *v > 0.0) {
        return tick_label(v);
    }
    let p = (2 - v.log10().floor() as i64).max(0) as usize;
    let s = format!("{v:.p$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_owned()
    } else {
        s
    }
}

/// The x range for core counts `lo..=hi`, with room for markers.
pub fn cores_range(lines: &[Line]) -> (f64, f64) {
    let (lo, hi) = x_extent(lines);
    (lo - 0.4, hi + 0.4)
}

/// The smallest and largest x of `lines` (1, 1 when empty).
pub fn x_extent(lines: &[Line]) -> (f64, f64) {
    let xs = lines.iter().flat_map(|l| l.points.iter().map(|p| p.x));
    let lo = xs.clone().fold(f64::INFINITY, f64::min);
    let hi = xs.fold(f64::NEG_INFINITY, f64::max);
    if lo.is_finite() { (lo, hi) } else { (1.0, 1.0) }
}

/// The largest upper spread (or value) of `lines`, or 1.
pub fn y_max(lines: &[Line]) -> f64 {
    let m = lines
        .iter()
        .flat_map(|l| l.points.iter().map(|p| p.hi.max(p.y)))
        .fold(f64::NEG_INFINITY, f64::max);
    if m.is_finite() && m > 0.0 { m } else { 1.0 }
}

/// The ticks of a cores axis spanning `lo..hi`: every whole number in it.
pub fn cores_keys(lo: f64, hi: f64) -> Vec<f64> {
    let (a, b) = (lo.ceil().max(0.0) as usize, hi.floor().max(0.0) as usize);
    (a..=b).map(|c| c as f64).collect()
}

/// The ticks of a logarithmic axis: the x values of `lines`, thinned so that neighbouring
/// labels stay at least 1/12 of the axis apart.
pub fn log_keys(lines: &[Line]) -> Vec<f64> {
    let mut xs: Vec<f64> = lines
        .iter()
        .flat_map(|l| l.points.iter().map(|p| p.x))
        .filter(|x| *x > 0.0)
        .collect();
    xs.sort_by(f64::total_cmp);
    xs.dedup();
    let (Some(&first), Some(&last)) = (xs.first(), xs.last()) else {
        return xs;
    };
    let gap = ((last / first).log10() + 2.0 * 1.3f64.log10()) / 12.0;
    let mut keys: Vec<f64> = Vec::new();
    for x in xs {
        if keys.last().is_none_or(|&k| x.log10() - k.log10() >= gap) {
            keys.push(x);
        }
    }
    keys
}

/// A linear cores axis whose ticks are the whole numbers in its range (and no minor lines).
#[derive(Debug, Clone, Copy)]
pub struct CoresAxis {
    lo: f64,
    hi: f64,
}

impl CoresAxis {
    /// The axis over `lo..hi`.
    pub fn new(lo: f64, hi: f64) -> CoresAxis {
        CoresAxis { lo, hi }
    }
}

impl Ranged for CoresAxis {
    type FormatOption = plotters::coord::ranged1d::DefaultFormatting;
    type ValueType = f64;

    fn map(&self, value: &f64, limit: (i32, i32)) -> i32 {
        let f = (value - self.lo) / (self.hi - self.lo);
        limit.0 + (f * f64::from(limit.1 - limit.0)).round() as i32
    }

    fn key_points<H: plotters::coord::ranged1d::KeyPointHint>(&self, hint: H) -> Vec<f64> {
        if hint.weight().allow_light_points() {
            Vec::new()
        } else {
            cores_keys(self.lo, self.hi)
        }
    }

    fn range(&self) -> std::ops::Range<f64> {
        self.lo..self.hi
    }
}

/// A plotted line: segments (solid, or dashed or dotted as its placement says: [`Dash`]),
/// dots (hollow when oversubscribed) and, with `bars`, vertical error bars over the spread.
pub fn draw_line<X, Y>(
    chart: &mut ChartContext<'_, BitMapBackend<'_>, Cartesian2d<X, Y>>,
    line: &Line,
    c: RGBColor,
    bars: bool,
) -> DrawResult
where
    X: Ranged<ValueType = f64>,
    Y: Ranged<ValueType = f64>,
{
    let pts: Vec<(f64, f64)> = line.points.iter().map(|p| (p.x, p.y)).collect();
    match Dash::of(line.pin()).pattern() {
        None => {
            chart.draw_series(LineSeries::new(pts, c.stroke_width(2)))?;
        }
        Some((on, off)) => {
            chart.draw_series(DashedLineSeries::new(pts, on, off, c.stroke_width(2)))?;
        }
    }
    if bars {
        chart.draw_series(
            line.points
                .iter()
                .filter(|p| p.hi > p.lo)
                .map(|p| ErrorBar::new_vertical(p.x, p.lo, p.y, p.hi, c.stroke_width(1), 10)),
        )?;
    }
    chart.draw_series(line.points.iter().flat_map(|p| dots(p, c)))?;
    Ok(())
}

/// A dashed reference line through `pts`.
pub fn draw_dashed<X, Y>(
    chart: &mut ChartContext<'_, BitMapBackend<'_>, Cartesian2d<X, Y>>,
    pts: Vec<(f64, f64)>,
    c: RGBColor,
) -> DrawResult
where
    X: Ranged<ValueType = f64>,
    Y: Ranged<ValueType = f64>,
{
    chart.draw_series(DashedLineSeries::new(pts, 8, 6, c.stroke_width(2)))?;
    Ok(())
}

/// A point's marker: a filled dot, or a hollow ring (white inside) when oversubscribed; a
/// red ring around it when contended.
pub fn dots(p: &Point, c: RGBColor) -> Vec<Circle<(f64, f64), i32>> {
    let mut out = if p.oversubscribed {
        vec![
            Circle::new((p.x, p.y), 6, WHITE.filled()),
            Circle::new((p.x, p.y), 6, c.stroke_width(2)),
        ]
    } else {
        vec![Circle::new((p.x, p.y), 4, c.filled())]
    };
    if p.contended {
        out.push(Circle::new((p.x, p.y), 9, CONTENDED.stroke_width(2)));
    }
    out
}

/// Axis text styles shared by every chart: (tick labels, axis descriptions).
pub fn axis_styles() -> (TextStyle<'static>, TextStyle<'static>) {
    (
        TextStyle::from((font::FAMILY, 14).into_font()),
        TextStyle::from((font::FAMILY, 16).into_font()),
    )
}
