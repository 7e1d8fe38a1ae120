//! `timeline.png`: a Gantt chart of a trace, drawn with plotters in the bundled font.
//!
//! Two panels with the same rows — one per worker (worker 0 at the top), then one for the
//! caller's serial work: above, the whole window of steps shown; below, a zoom into the middle
//! of the last shown step's density pass, about a dozen kernel calls per worker wide (at most
//! the whole pass), so that single tasks and the gaps between them show even for
//! `rayon-spawn` (the zoomed span is outlined in red above). One bar per kernel call, coloured
//! by pass (and the grid's rebuild), alternating a lighter and darker shade from one call to
//! the next on a worker so that back-to-back chunks stay distinguishable; white where a
//! worker is idle; a dashed vertical line at the start of every step. The x axes are
//! milliseconds since the step loop started. Bars are at least one pixel wide, so even
//! sub-pixel tasks show.

use std::io::Write;
use std::ops::RangeInclusive;

use anyhow::Context;
use plotters::coord::Shift;
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::font;
use sph_harness::trace::TraceConfig;
use sph_harness::trace::chrome::worker_track_name;
use sph_harness::trace::recorder::{Phase, SerialWork, Trace};
use sph_harness::trace::stats::WorkerStats;
use sph_solver::solver::Pass;

/// Width of the image in pixels.
pub const WIDTH: u32 = 1600;
const HEADER_PX: u32 = 84;
const TOP_PX: u32 = 40;
const ROW_PX: u32 = 56;
const AXIS_PX: u32 = 64;
const LABEL_AREA_PX: u32 = 250;
const BAR_HALF_HEIGHT: f64 = 0.32;
/// Kernel calls per worker that the zoom panel spans, about.
const ZOOM_CALLS: f64 = 12.0;

/// The image size for `tracks` rows (workers + the caller): [`WIDTH`] ×
/// (84 + 2 × (104 + 56 × tracks)) pixels.
pub fn image_size(tracks: usize) -> (u32, u32) {
    let tracks = u32::try_from(tracks).unwrap_or(u32::MAX / ROW_PX / 4);
    (WIDTH, HEADER_PX + 2 * panel_height(tracks))
}

fn panel_height(tracks: u32) -> u32 {
    TOP_PX + ROW_PX * tracks + AXIS_PX
}

/// A phase's colour, in a lighter (`dark = false`) or darker shade.
fn phase_color(phase: Phase, dark: bool) -> RGBColor {
    let (light, darker) = match phase {
        Phase::Rebuild => (RGBColor(170, 130, 210), RGBColor(118, 78, 160)),
        Phase::Pass(Pass::Density) => (RGBColor(66, 146, 214), RGBColor(31, 96, 160)),
        Phase::Pass(Pass::Forces) => (RGBColor(255, 150, 50), RGBColor(204, 102, 0)),
        Phase::Pass(Pass::Integrate) => (RGBColor(60, 180, 60), RGBColor(25, 120, 25)),
        Phase::Pass(Pass::MaxSpeed) => (RGBColor(150, 150, 150), RGBColor(90, 90, 90)),
        Phase::Pass(Pass::Neighbors) => (RGBColor(170, 130, 210), RGBColor(118, 78, 160)),
        Phase::Pass(Pass::Walls) => (RGBColor(140, 100, 70), RGBColor(96, 64, 40)),
        Phase::Pass(Pass::Momentum) => (RGBColor(255, 150, 50), RGBColor(204, 102, 0)),
        Phase::Pass(Pass::Continuity) => (RGBColor(66, 146, 214), RGBColor(31, 96, 160)),
    };
    if dark { darker } else { light }
}

fn serial_color(work: SerialWork) -> RGBColor {
    match work {
        SerialWork::Rebuild => RGBColor(120, 120, 120),
        SerialWork::Check => RGBColor(190, 190, 190),
    }
}

fn ms(ns: u64) -> f64 {
    ns as f64 / 1e6
}

/// Draws the steps `steps` (1-based, inclusive; clamped to the traced ones) of `trace` and
/// writes the PNG to `out`. `workers` names the rows (from [`sph_harness::trace::stats::compute`]).
pub fn write_png<W: Write>(
    trace: &Trace,
    workers: &[WorkerStats],
    config: &TraceConfig,
    steps: RangeInclusive<usize>,
    out: W,
) -> anyhow::Result<()> {
    font::ensure_registered()?;
    let (w, h) = image_size(trace.workers + 1);
    let mut pixels = vec![0u8; w as usize * h as usize * 3];
    draw(trace, workers, config, steps, &mut pixels, (w, h))
        .map_err(|e| anyhow::anyhow!("{e}"))
        .context("cannot draw the timeline")?;
    let mut encoder = png::Encoder::new(out, w, h);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    let mut writer = encoder.write_header()?;
    writer.write_image_data(&pixels)?;
    writer.finish()?;
    Ok(())
}

type DrawResult = Result<(), Box<dyn std::error::Error>>;

/// The span of the events of `steps`, in ns (the whole loop if there are none).
fn window(trace: &Trace, steps: &RangeInclusive<usize>) -> (u64, u64) {
    let kernels = trace.kernels.iter().map(|e| (e.step, e.start_ns, e.end_ns));
    let serial = trace.serial.iter().map(|e| (e.step, e.start_ns, e.end_ns));
    let (t0, t1) = kernels
        .chain(serial)
        .filter(|(step, _, _)| steps.contains(step))
        .fold((u64::MAX, 0), |(lo, hi), (_, s, e)| (lo.min(s), hi.max(e)));
    if t0 > t1 {
        (0, trace.wall_ns)
    } else {
        (t0, t1)
    }
}

/// The zoom: about [`ZOOM_CALLS`] kernel calls per worker wide, centred on the middle of the
/// last shown step's density pass, inside `full`; in ns, with a description.
fn zoom_window(trace: &Trace, step: usize, full: (u64, u64)) -> ((u64, u64), String) {
    let density: Vec<_> = trace
        .kernels
        .iter()
        .filter(|e| e.step == step && e.phase == Phase::Pass(Pass::Density))
        .collect();
    let Some(start) = density.iter().map(|e| e.start_ns).min() else {
        return (full, "zoom: no density pass in the window".to_owned());
    };
    let end = density.iter().map(|e| e.end_ns).max().unwrap_or(start);
    let per_worker = (density.len() as f64 / trace.workers.max(1) as f64).max(1.0);
    // At most the whole pass and a margin, so that a pass of few calls is shown whole.
    let span = (end - start) as f64;
    let width = (span / per_worker * ZOOM_CALLS)
        .min(span * 1.1)
        .clamp(1000.0, (full.1 - full.0).max(1000) as f64) as u64;
    let mid = start + (end - start) / 2;
    let lo = mid.saturating_sub(width / 2).max(full.0);
    let hi = (lo + width).min(full.1.max(lo + 1000));
    let width_us = (hi - lo) as f64 / 1e3;
    let width = if width_us < 1000.0 {
        format!("{width_us:.1} µs")
    } else {
        format!("{:.2} ms", width_us / 1e3)
    };
    let what = format!(
        "zoom: {width} in the middle of step {step}'s density pass ({} kernel calls in that pass)",
        density.len()
    );
    ((lo, hi), what)
}

fn draw(
    trace: &Trace,
    workers: &[WorkerStats],
    config: &TraceConfig,
    steps: RangeInclusive<usize>,
    pixels: &mut [u8],
    size: (u32, u32),
) -> DrawResult {
    let tracks = trace.workers + 1;
    let mut labels: Vec<String> = workers.iter().map(worker_track_name).collect();
    labels.resize(trace.workers, String::new());
    labels.push("serial (between passes)".to_owned());

    let root = BitMapBackend::with_buffer(pixels, size).into_drawing_area();
    root.fill(&WHITE)?;
    let (header, body) = root.split_vertically(HEADER_PX);
    draw_header(&header, trace, config, &steps)?;
    let (top, bottom) = body.split_vertically(panel_height(tracks as u32));

    let full = window(trace, &steps);
    let last_step = trace
        .serial
        .iter()
        .map(|e| e.step)
        .filter(|s| steps.contains(s))
        .max()
        .unwrap_or(*steps.end());
    let (zoom, zoom_title) = zoom_window(trace, last_step, full);
    let panel = Panel {
        trace,
        labels: &labels,
        steps: &steps,
    };
    panel.draw(&root, &top, full, None, Some(zoom))?;
    panel.draw(&root, &bottom, zoom, Some(&zoom_title), None)?;
    root.present()?;
    Ok(())
}

/// What every panel draws.
struct Panel<'a> {
    trace: &'a Trace,
    labels: &'a [String],
    steps: &'a RangeInclusive<usize>,
}

/// A panel's plot: milliseconds across, one row per track (worker 0 at the top).
type Plot<'a, 'b> =
    ChartContext<'a, BitMapBackend<'b>, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

/// The image, for text placed in pixels.
type Root<'b> = DrawingArea<BitMapBackend<'b>, Shift>;

impl Panel<'_> {
    /// Draws the rows over `(t0, t1)` ns into `area`; `title` above the plot; `outline` a span
    /// to outline in red. `root` is the whole image, for text placed in pixels.
    fn draw(
        &self,
        root: &Root<'_>,
        area: &Root<'_>,
        (t0, t1): (u64, u64),
        title: Option<&str>,
        outline: Option<(u64, u64)>,
    ) -> DrawResult {
        let tracks = self.trace.workers + 1;
        let (x0, x1) = (ms(t0), ms(t1).max(ms(t0) + 1e-6));
        // Enough decimals that neighbouring tick labels differ.
        let decimals = ((-(x1 - x0).log10()).ceil() + 2.0).clamp(1.0, 6.0) as usize;

        let mut chart = ChartBuilder::on(area)
            .margin_top(TOP_PX)
            .margin_right(30)
            .x_label_area_size(AXIS_PX)
            .y_label_area_size(LABEL_AREA_PX)
            .build_cartesian_2d(x0..x1, 0.0..tracks as f64)?;
        chart
            .configure_mesh()
            .disable_y_mesh()
            .y_labels(0)
            .x_labels(12)
            .x_label_formatter(&|x| format!("{x:.decimals$}"))
            .x_desc("time since the step loop started (ms)")
            .label_style((font::FAMILY, 16))
            .axis_desc_style((font::FAMILY, 17))
            .light_line_style(RGBColor(235, 235, 235))
            .bold_line_style(RGBColor(215, 215, 215))
            .draw()?;

        self.draw_labels(root, &chart, x0, title)?;
        self.draw_bars(&mut chart, (t0, t1))?;
        self.draw_step_starts(root, &mut chart, (t0, t1), title.is_none())?;
        if let Some((lo, hi)) = outline {
            chart.draw_series([Rectangle::new(
                [(ms(lo), tracks as f64 - 0.02), (ms(hi), 0.02)],
                RED.stroke_width(2),
            )])?;
        }
        Ok(())
    }

    /// The y coordinate of the middle of `row`'s bars.
    fn centre(&self, row: usize) -> f64 {
        (self.trace.workers + 1 - row) as f64 - 0.5
    }

    /// Whether work of `step` over `s..e` ns shows in the panel's window `(t0, t1)`.
    fn visible(&self, step: usize, (s, e): (u64, u64), (t0, t1): (u64, u64)) -> bool {
        self.steps.contains(&step) && e >= t0 && s <= t1
    }

    /// Row names, right-aligned beside the plot, and `title` above it.
    fn draw_labels(
        &self,
        root: &Root<'_>,
        chart: &Plot<'_, '_>,
        x0: f64,
        title: Option<&str>,
    ) -> DrawResult {
        let row_style = TextStyle::from((font::FAMILY, 16).into_font())
            .color(&BLACK)
            .pos(Pos::new(HPos::Right, VPos::Center));
        for (row, label) in self.labels.iter().enumerate() {
            let (px, py) = chart.backend_coord(&(x0, self.centre(row)));
            root.draw(&Text::new(label.as_str(), (px - 12, py), row_style.clone()))?;
        }
        if let Some(title) = title {
            let tracks = self.trace.workers + 1;
            let (px, py) = chart.backend_coord(&(x0, tracks as f64));
            let style = TextStyle::from((font::FAMILY, 17).into_font()).color(&BLACK);
            root.draw(&Text::new(title, (px, py - 30), style))?;
        }
        Ok(())
    }

    /// One bar per kernel call on its worker's row, alternating shades per worker (counted
    /// over the whole trace, so a call has the same shade in both panels); the caller's serial
    /// work on the last row.
    fn draw_bars(&self, chart: &mut Plot<'_, '_>, (t0, t1): (u64, u64)) -> DrawResult {
        let trace = self.trace;
        let bar = |row: usize, (s, e): (u64, u64), color: RGBColor| {
            let y = self.centre(row);
            Rectangle::new(
                [
                    (ms(s.max(t0)), y + BAR_HALF_HEIGHT),
                    (ms(e.min(t1)), y - BAR_HALF_HEIGHT),
                ],
                color.filled(),
            )
        };
        let mut nth = vec![0usize; trace.workers];
        let mut bars = Vec::new();
        for e in &trace.kernels {
            let dark = nth[e.worker] % 2 == 1;
            nth[e.worker] += 1;
            let span = (e.start_ns, e.end_ns);
            if self.visible(e.step, span, (t0, t1)) {
                bars.push(bar(e.worker, span, phase_color(e.phase, dark)));
            }
        }
        chart.draw_series(bars)?;
        let serial = trace
            .serial
            .iter()
            .filter(|e| self.visible(e.step, (e.start_ns, e.end_ns), (t0, t1)))
            .map(|e| bar(trace.workers, (e.start_ns, e.end_ns), serial_color(e.work)));
        chart.draw_series(serial)?;
        Ok(())
    }

    /// Step starts: a dashed line from the bottom to the top of the plot, labelled above
    /// when `labelled`.
    fn draw_step_starts(
        &self,
        root: &Root<'_>,
        chart: &mut Plot<'_, '_>,
        (t0, t1): (u64, u64),
        labelled: bool,
    ) -> DrawResult {
        let tracks = self.trace.workers + 1;
        let label_style = TextStyle::from((font::FAMILY, 15).into_font()).color(&BLACK);
        let starts = self.trace.serial.iter().filter(|e| {
            e.work == SerialWork::Rebuild
                && self.steps.contains(&e.step)
                && (t0..=t1).contains(&e.start_ns)
        });
        for e in starts {
            let x = ms(e.start_ns);
            chart.draw_series(DashedLineSeries::new(
                [(x, 0.0), (x, tracks as f64)],
                6,
                4,
                BLACK.stroke_width(1),
            ))?;
            if labelled {
                let (px, py) = chart.backend_coord(&(x, tracks as f64));
                root.draw(&Text::new(
                    format!("step {}", e.step),
                    (px + 4, py - 22),
                    label_style.clone(),
                ))?;
            }
        }
        Ok(())
    }
}

/// Title and legend.
fn draw_header<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    trace: &Trace,
    config: &TraceConfig,
    steps: &RangeInclusive<usize>,
) -> DrawResult
where
    DB::ErrorType: 'static,
{
    let last = trace.serial.iter().map(|e| e.step).max().unwrap_or(0);
    let (first, shown_last) = (*steps.start(), (*steps.end()).min(last));
    let which = if first <= 1 && shown_last >= last {
        format!("{} steps", config.steps)
    } else if first == shown_last {
        format!("step {first} of {}", config.steps)
    } else {
        format!("steps {first}–{shown_last} of {}", config.steps)
    };
    let title = format!("Timeline: {}, {which}", config.title());
    area.draw(&Text::new(
        title,
        (20, 12),
        TextStyle::from((font::FAMILY, 24).into_font()).color(&BLACK),
    ))?;
    let style = TextStyle::from((font::FAMILY, 16).into_font()).color(&BLACK);
    let swatches = trace
        .phases()
        .into_iter()
        .map(|p| (p.as_str(), phase_color(p, false)))
        .chain([SerialWork::Rebuild, SerialWork::Check].map(|s| (s.as_str(), serial_color(s))));
    let mut x = 20;
    let y = 54;
    for (label, color) in swatches {
        area.draw(&Rectangle::new([(x, y), (x + 22, y + 16)], color.filled()))?;
        area.draw(&Text::new(label, (x + 30, y), style.clone()))?;
        let (tw, _) = area.estimate_text_size(label, &style)?;
        x += 30 + tw as i32 + 36;
    }
    for dx in (0..24).step_by(8) {
        area.draw(&PathElement::new(
            [(x + dx, y + 8), (x + dx + 5, y + 8)],
            BLACK.stroke_width(1),
        ))?;
    }
    area.draw(&Text::new("step start", (x + 30, y), style.clone()))?;
    let (tw, _) = area.estimate_text_size("step start", &style)?;
    x += 30 + tw as i32 + 36;
    area.draw(&Rectangle::new(
        [(x, y), (x + 22, y + 16)],
        RED.stroke_width(2),
    ))?;
    area.draw(&Text::new("zoomed below", (x + 30, y), style.clone()))?;
    let (tw, _) = area.estimate_text_size("zoomed below", &style)?;
    x += 30 + tw as i32 + 36;
    area.draw(&Text::new("white: idle", (x, y), style))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use sph_harness::trace::recorder::{KernelEvent, SerialEvent, ThreadInfo};
    use sph_solver::models::Preset;
    use sph_solver::sph::neighbors::NeighborMode;

    /// The phases of a step of Müller's model on the grid.
    const PHASES: [Phase; 3] = [
        Phase::Rebuild,
        Phase::Pass(Pass::Density),
        Phase::Pass(Pass::Forces),
    ];

    /// Two steps on two workers: per step a grid rebuild, then density and forces
    /// calls of 100 µs each, with the caller's rebuild and check between them.
    fn trace() -> Trace {
        let mut kernels = Vec::new();
        let mut serial = Vec::new();
        for step in 1..=2u64 {
            let t = (step - 1) * 1_000_000;
            serial.push(SerialEvent {
                work: SerialWork::Rebuild,
                step: step as usize,
                start_ns: t,
                end_ns: t + 50_000,
            });
            for (k, &phase) in PHASES.iter().enumerate() {
                for worker in 0..2 {
                    let start_ns = t + 100_000 + k as u64 * 200_000 + worker as u64 * 20_000;
                    kernels.push(KernelEvent {
                        phase,
                        step: step as usize,
                        worker,
                        thread: worker,
                        first: worker * 5,
                        len: 5,
                        start_ns,
                        end_ns: start_ns + 100_000,
                    });
                }
            }
            serial.push(SerialEvent {
                work: SerialWork::Check,
                step: step as usize,
                start_ns: t + 900_000,
                end_ns: t + 950_000,
            });
        }
        Trace {
            kernels,
            serial,
            threads: (0..2)
                .map(|worker| ThreadInfo {
                    name: format!("rayon-chunks-{worker}"),
                    worker,
                })
                .collect(),
            workers: 2,
            wall_ns: 2_000_000,
        }
    }

    fn config() -> TraceConfig {
        TraceConfig {
            strategy: "rayon-chunks".into(),
            cores: 2,
            chunks: Some(2),
            n: 10,
            steps: 2,
            preset: Preset::Seed,
            neighbors: NeighborMode::Grid,
            seed: Some(2019),
            init: None,
        }
    }

    #[test]
    fn a_timeline_shows_each_kernel_call_as_a_bar_of_its_pass_colour_on_its_worker_s_row() {
        let trace = trace();
        let stats = sph_harness::trace::stats::compute(&trace);
        font::ensure_registered().unwrap();
        let (w, h) = image_size(3);
        let mut pixels = vec![0u8; w as usize * h as usize * 3];
        draw(
            &trace,
            &stats.workers,
            &config(),
            1..=2,
            &mut pixels,
            (w, h),
        )
        .unwrap();
        let mut bytes = Vec::new();
        write_png(&trace, &stats.workers, &config(), 1..=2, &mut bytes).unwrap();
        assert_eq!(&bytes[..8], sph_harness::output::sniff::PNG_SIGNATURE);
        if let Ok(path) = std::env::var("TIMELINE_PNG") {
            std::fs::write(path, &bytes).unwrap();
        }
        let colour_count = |c: RGBColor| {
            pixels
                .chunks_exact(3)
                .filter(|p| p == &[c.0, c.1, c.2])
                .count()
        };
        // Every phase shows in both shades: a worker alternates them from call to call, and a
        // step has three calls (the first step's rebuild and forces light, density dark; the
        // second's the other way round).
        for (&phase, dark) in PHASES.iter().flat_map(|p| [(p, false), (p, true)]) {
            let n = colour_count(phase_color(phase, dark));
            assert!(n > 100, "{phase:?} dark={dark}: {n} pixels");
        }
        for work in [SerialWork::Rebuild, SerialWork::Check] {
            assert!(colour_count(serial_color(work)) > 100, "{work:?}");
        }
    }
}
