//! One frame of an animation: a particle state → an RGB image. Pure: no I/O, no clock.
//!
//! Müller's presets (pixel units), as the seed program drew them:
//!
//! ```text
//!  step 300 · t = 0.270 s · N = 1000 · seed preset        ← caption
//! ┏━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━┓
//! ┃  ●●●                                                ┃  ← the tank, y up, walls drawn
//! ┃ ●●●●●●●                                             ┃    around its inside; particles
//! ┃●●●●●●●●●●●●●●                                       ┃    are discs of radius H/2
//! ┗━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━┛
//!  speed, px/s   0 ▕██████████████▏ 14222                 ← legend: the colour scale
//! ```
//!
//! `wcsph` (SI units): the drawn area is the tank's inside and the walls' layers of fixed
//! particles left, right and below it, the walls in grey, the fluid as discs of radius dx/2
//! (neighbours touch), with axes in metres whose 0 is the inner faces of the left wall and
//! the floor:
//!
//! ```text
//!    step 400 · t = 0.262 s · N = 128 · wcsph preset       ← caption (time: the solver's sum of dt)
//!  2 m ┤░░                                            ░░
//!      ┤░░●●●●                                        ░░  ← walls: grey particles
//!  1   ┤░░●●●●●●●●●                                   ░░
//!      ┤░░●●●●●●●●●●●●●●●●●●                          ░░
//!  0   ┤░░░░░░░░░░░░░░░░░░░░░░░░░░░░░░░░░░░░░░░░░░░░░░░░
//!         ┬     ┬     ┬     ┬     ┬     ┬
//!         0     1     2     3     4    5 m               ← x axis, m
//!  speed, m/s   0.0 ▕██████████████▏ 6.3                 ← legend
//! ```
//!
//! The image width is chosen; the drawn area fills it less the margins (and the axes' labels)
//! and its height follows the area's aspect ratio, so a frame is `width × height(width, tank)`
//! for the whole animation.

use std::fmt;

use crate::render::colormap::Colormap;
use crate::render::image::{Image, Rect};
use crate::render::scale::Scale;
use crate::render::text;
use sph_solver::models::Physics;
use sph_solver::models::Preset;
use sph_solver::scene::Scene;
use sph_solver::solver::Simulation;
use sph_solver::sph::state::{Domain, State};

/// Narrowest frame, px: the caption and the legend need this much.
pub const MIN_WIDTH: u32 = 360;
/// Widest frame, px (GIF sizes are 16-bit; this also bounds memory).
pub const MAX_WIDTH: u32 = 4096;

const BACKGROUND: [u8; 3] = [255, 255, 255];
const WALL: [u8; 3] = [64, 64, 64];
/// `wcsph`'s wall particles: a neutral grey, lighter than any viridis colour's contrast with
/// the bars (one of the palette's greys).
pub const WALL_PARTICLE: [u8; 3] = [168, 168, 168];
const TEXT: [u8; 3] = [0, 0, 0];

/// Most ticks along an axis.
const MAX_TICKS: f64 = 8.0;

/// What a frame's caption says.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Caption {
    /// Steps completed.
    pub step: usize,
    /// Simulated time, s (Müller: `step · DT`; `wcsph`: the sum of its adaptive time steps).
    pub time_s: f64,
    /// Number of particles that move (`wcsph`'s fixed wall particles are not counted).
    pub n: usize,
    /// The constants in use.
    pub preset: Preset,
}

impl Caption {
    /// The caption of a simulation of `physics` holding `n` particles (walls included) after
    /// `step` steps that simulated `time_s` seconds. Müller's time is `step · DT` (exactly
    /// as the seed program shows it); `wcsph`'s time step adapts, so its time is `time_s`.
    pub fn new(physics: &Physics, step: usize, time_s: f64, n: usize) -> Caption {
        let time_s = physics.fixed_dt().map_or(time_s, |dt| step as f64 * dt);
        Caption {
            step,
            time_s,
            n: physics.fluid(n),
            preset: physics.preset(),
        }
    }

    /// The caption of `sim` now.
    pub fn of(sim: &Simulation) -> Caption {
        Caption::new(&sim.physics, sim.steps_done, sim.time_s, sim.state.len())
    }
}

impl fmt::Display for Caption {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "step {} · t = {:.3} s · N = {} · {} preset",
            self.step, self.time_s, self.n, self.preset
        )
    }
}

/// How a model's walls are drawn.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Walls {
    /// Müller: the walls are the domain's edges, drawn as dark bars around it; every particle
    /// is fluid.
    Bars,
    /// `wcsph`: fixed particles, from index `fluid` on, in layers `thickness` deep (model
    /// units) outside the left, right and bottom faces; drawn as grey particles, with axes.
    Particles {
        /// Particles before this index are fluid.
        fluid: usize,
        /// Depth of the wall layers, model units.
        thickness: f64,
    },
}

/// What a frame shows of a simulation, in the model's units: the plan a [`Layout`] is made
/// from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct View {
    /// The tank's inside: x from 0 to `width`, y from 0 to `height`.
    pub domain: Domain,
    /// Particle radius, model units (Müller: H/2, px; `wcsph`: dx/2, m).
    pub radius: f64,
    /// How the walls are drawn.
    pub walls: Walls,
}

impl View {
    /// The view of `scene`: walls outside the domain are drawn as the particles they are,
    /// walls at its edges as bars.
    pub fn of(scene: &Scene) -> View {
        let physics = &scene.physics;
        let depth = physics.wall_depth();
        View {
            domain: scene.domain,
            radius: physics.drawn_radius(),
            walls: if depth > 0.0 {
                Walls::Particles {
                    fluid: scene.fluid(),
                    thickness: depth,
                }
            } else {
                Walls::Bars
            },
        }
    }
}

/// Axes along the bottom and the left of the drawn area, ticks every `step` model units from
/// 0 to the domain's width and height, the last label of each followed by the unit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Axes {
    /// Distance between ticks, model units (1, 2 or 5 × a power of ten).
    pub step: f64,
    /// Decimals the labels need for `step`.
    decimals: usize,
    /// The last tick along x and along y, model units.
    ends: (f64, f64),
    /// The unit the last labels name.
    unit: &'static str,
    /// Length of a tick mark, px.
    tick: u32,
}

impl Axes {
    /// Ticks for `domain` in metres: the finest 1–2–5 step with at most [`MAX_TICKS`]
    /// intervals across the width.
    fn metres(domain: Domain, tick: u32) -> Axes {
        let rough = domain.width / MAX_TICKS;
        let decade = 10f64.powf(rough.log10().floor());
        let step = [1.0, 2.0, 5.0, 10.0]
            .into_iter()
            .map(|m| m * decade)
            .find(|&s| s >= rough * (1.0 - 1e-9))
            .unwrap_or(10.0 * decade);
        let decimals = (-step.log10().floor()).max(0.0) as usize;
        let last = |extent: f64| (extent / step + 1e-9).floor() * step;
        Axes {
            step,
            decimals,
            ends: (last(domain.width), last(domain.height)),
            unit: "m",
            tick,
        }
    }

    /// The ticks along an axis ending at `end`: each value, model units, and its label.
    fn ticks(&self, end: f64) -> Vec<(f64, String)> {
        let count = (end / self.step).round() as usize;
        (0..=count)
            .map(|k| {
                let value = k as f64 * self.step;
                let mut label = format!("{value:.*}", self.decimals);
                if k == count {
                    label = format!("{label} {}", self.unit);
                }
                (value, label)
            })
            .collect()
    }

    /// The ticks along x.
    pub fn x_ticks(&self) -> Vec<(f64, String)> {
        self.ticks(self.ends.0)
    }

    /// The ticks along y.
    pub fn y_ticks(&self) -> Vec<(f64, String)> {
        self.ticks(self.ends.1)
    }
}

/// Where things go in a frame, px (image coordinates: x right, y down).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Layout {
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// The drawn area. Müller: the inside of the tank, the domain's [0, width] × [0, height],
    /// y flipped, with the walls drawn outside it. `wcsph`: the domain and the walls' layers.
    pub tank: Rect,
    /// Thickness of the wall bars drawn outside `tank` (0 where the walls are particles).
    pub wall: u32,
    /// Image px per model unit.
    pub zoom: f64,
    /// Particle radius, image px.
    pub radius: f64,
    /// Text height.
    pub font_px: f64,
    /// Left edge of the caption and the legend (and of the viewer's status lines).
    pub text_x: u32,
    /// Axes in the model's units, where it has them (`wcsph`).
    pub axes: Option<Axes>,
    /// The model coordinates of `tank`'s left and top edges (to place and flip y).
    left: f64,
    top: f64,
    /// First row of the legend's band.
    legend_top: u32,
}

impl Layout {
    /// The layout of a `width`-px frame of `view`. `width` is clamped to [`MIN_WIDTH`,
    /// `MAX_WIDTH`].
    pub fn new(view: &View, width: u32) -> Layout {
        let width = width.clamp(MIN_WIDTH, MAX_WIDTH);
        let font_px = (f64::from(width) / 40.0).max(11.0);
        let margin = (font_px * 0.8).round() as u32;
        let caption_band = (font_px * 2.0).round() as u32;
        let legend_band = (font_px * 2.4).round() as u32;
        let domain = view.domain;
        let Walls::Particles { thickness, .. } = view.walls else {
            let wall = (width / 200).max(2);
            let inner = width - 2 * margin;
            let zoom = f64::from(inner) / domain.width;
            // A very wide tank (huge N) still gets one row of pixels.
            let tank_h = ((domain.height * zoom).round() as u32).clamp(1, 4 * MAX_WIDTH);
            let tank = Rect {
                x0: margin,
                y0: caption_band + wall,
                x1: margin + inner,
                y1: caption_band + wall + tank_h,
            };
            return Layout {
                width,
                height: tank.y1 + wall + legend_band,
                tank,
                wall,
                zoom,
                radius: view.radius * zoom,
                font_px,
                text_x: margin,
                axes: None,
                left: 0.0,
                top: domain.height,
                legend_top: tank.y1 + wall,
            };
        };
        // Room for the y labels on the left, half the last x label on the right.
        let tick = (0.4 * font_px).round().max(2.0) as u32;
        let axes = Axes::metres(domain, tick);
        let widest = |ticks: Vec<(f64, String)>| {
            ticks
                .iter()
                .map(|(_, label)| text::width(label, font_px))
                .fold(0.0, f64::max)
        };
        let y_labels = widest(axes.y_ticks()) + 0.4 * font_px;
        let x_last = axes
            .x_ticks()
            .pop()
            .map_or(0.0, |(_, l)| text::width(&l, font_px));
        let left = margin + tick + y_labels.ceil() as u32;
        let right = margin.max((0.5 * x_last).ceil() as u32);
        let inner = width.saturating_sub(left + right).max(1);
        let area = (domain.width + 2.0 * thickness, domain.height + thickness);
        let zoom = f64::from(inner) / area.0;
        let area_h = ((area.1 * zoom).round() as u32).clamp(1, 4 * MAX_WIDTH);
        let tank = Rect {
            x0: left,
            y0: caption_band,
            x1: left + inner,
            y1: caption_band + area_h,
        };
        let axis_band = tick + (1.6 * font_px).round() as u32;
        let legend_top = tank.y1 + axis_band;
        Layout {
            width,
            height: legend_top + legend_band,
            tank,
            wall: 0,
            zoom,
            radius: view.radius * zoom,
            font_px,
            text_x: margin,
            axes: Some(axes),
            left: -thickness,
            top: domain.height,
            legend_top,
        }
    }

    /// Where the model point (`x`, `y`) lands in the image (y up in the model, down here).
    pub fn to_image(&self, x: f64, y: f64) -> (f64, f64) {
        (
            f64::from(self.tank.x0) + (x - self.left) * self.zoom,
            f64::from(self.tank.y0) + (self.top - y) * self.zoom,
        )
    }
}

/// Draws frames of one animation: a layout, a colour scale and a colour map.
#[derive(Debug, Clone)]
pub struct Painter {
    view: View,
    layout: Layout,
    scale: Scale,
    colormap: Colormap,
}

impl Painter {
    /// A painter for `width`-px frames of `view`, colouring by `scale`.
    pub fn new(view: View, scale: Scale, width: u32) -> Painter {
        Painter {
            view,
            layout: Layout::new(&view, width),
            scale,
            colormap: Colormap::viridis(),
        }
    }

    /// Where things go.
    pub fn layout(&self) -> &Layout {
        &self.layout
    }

    /// Every colour a frame is made of: the colour map, then 65 greys from black to white
    /// (background, walls, wall particles, and the shades of anti-aliased black text on white).
    pub fn palette(&self) -> Vec<[u8; 3]> {
        let greys = (0..=64u32).map(|k| [(k * 4).min(255) as u8; 3]);
        self.colormap
            .colors()
            .iter()
            .copied()
            .chain(greys)
            .collect()
    }

    /// The colour of particle `i` of `state`: its value on the scale, or grey for a wall.
    pub fn color(&self, state: &State, i: usize) -> [u8; 3] {
        match self.view.walls {
            Walls::Particles { fluid, .. } if i >= fluid => WALL_PARTICLE,
            _ => self
                .colormap
                .color(self.scale.fraction(self.scale.value(state, i))),
        }
    }

    /// The frame showing `state`, captioned `caption`.
    pub fn draw(&self, state: &State, caption: &Caption) -> Image {
        let l = &self.layout;
        let mut img = Image::filled(l.width, l.height, BACKGROUND);
        let t = l.tank;
        let (first, then) = match self.view.walls {
            Walls::Bars => {
                let walls = Rect {
                    x0: t.x0 - l.wall,
                    y0: t.y0 - l.wall,
                    x1: t.x1 + l.wall,
                    y1: t.y1 + l.wall,
                };
                img.fill_rect(walls, WALL);
                img.fill_rect(t, BACKGROUND);
                (0..0, 0..state.len())
            }
            // The walls first: fluid pressed against them stays in sight.
            Walls::Particles { fluid, .. } => {
                let fluid = fluid.min(state.len());
                (fluid..state.len(), 0..fluid)
            }
        };
        for i in first.chain(then) {
            let (cx, cy) = l.to_image(state.x[i], state.y[i]);
            img.fill_disc(cx, cy, l.radius, t, self.color(state, i));
        }
        if let Some(axes) = &l.axes {
            self.draw_axes(&mut img, axes);
        }
        self.draw_caption(&mut img, &caption.to_string());
        self.draw_legend(&mut img);
        img
    }

    /// Tick marks below and left of the drawn area, and their labels.
    fn draw_axes(&self, img: &mut Image, axes: &Axes) {
        let l = &self.layout;
        let em = l.font_px;
        let t = l.tank;
        let cap = text::cap_height(em);
        for (x, label) in axes.x_ticks() {
            let (px, _) = l.to_image(x, 0.0);
            let column = px.round() as u32;
            let mark = Rect {
                x0: column.saturating_sub(1),
                y0: t.y1,
                x1: column + 1,
                y1: t.y1 + axes.tick,
            };
            img.fill_rect(mark, TEXT);
            let at = px - text::width(&label, em) / 2.0;
            let baseline = f64::from(t.y1 + axes.tick) + 0.3 * em + cap;
            text::draw(img, &label, (at, baseline), em, TEXT);
        }
        for (y, label) in axes.y_ticks() {
            let (_, py) = l.to_image(0.0, y);
            let row = py.round() as u32;
            let mark = Rect {
                x0: t.x0 - axes.tick,
                y0: row.saturating_sub(1),
                x1: t.x0,
                y1: row + 1,
            };
            img.fill_rect(mark, TEXT);
            let at = f64::from(t.x0 - axes.tick) - 0.3 * em - text::width(&label, em);
            text::draw(img, &label, (at, py + cap / 2.0), em, TEXT);
        }
    }

    /// The caption, centred vertically in the band above the tank.
    fn draw_caption(&self, img: &mut Image, caption: &str) {
        let l = &self.layout;
        let band = f64::from(l.tank.y0 - l.wall);
        let baseline = (band + text::cap_height(l.font_px)) / 2.0;
        text::draw(
            img,
            caption,
            (f64::from(l.text_x), baseline),
            l.font_px,
            TEXT,
        );
    }

    /// "title   lo [colour bar] hi", centred vertically in the band below the tank.
    fn draw_legend(&self, img: &mut Image) {
        let l = &self.layout;
        let s = &self.scale;
        let (title, lo, hi) = (s.title(), s.label(s.lo), s.label(s.hi));
        let em = l.font_px;
        let mid = f64::from(l.legend_top + l.height) / 2.0;
        let baseline = mid + text::cap_height(em) / 2.0;

        let title_x = f64::from(l.text_x);
        let lo_x = title_x + text::width(title, em) + 2.0 * em;
        let bar_x0 = (lo_x + text::width(&lo, em) + 0.5 * em).round() as u32;
        let bar_w = l.width / 3;
        let hi_x = f64::from(bar_x0 + bar_w) + 0.5 * em;
        let half = (0.4 * em).round().max(3.0);
        let (bar_y0, bar_y1) = ((mid - half).round() as u32, (mid + half).round() as u32);
        for x in 0..bar_w {
            let color = self
                .colormap
                .color(f64::from(x) / f64::from(bar_w.saturating_sub(1).max(1)));
            let column = Rect {
                x0: bar_x0 + x,
                y0: bar_y0,
                x1: bar_x0 + x + 1,
                y1: bar_y1,
            };
            img.fill_rect(column, color);
        }
        text::draw(img, title, (title_x, baseline), em, TEXT);
        text::draw(img, &lo, (lo_x, baseline), em, TEXT);
        text::draw(img, &hi, (hi_x, baseline), em, TEXT);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::scale::ColorBy;

    const TANK: Domain = Domain {
        width: 1200.0,
        height: 900.0,
    };

    fn painter(by: ColorBy, state: &State) -> Painter {
        let physics = Physics::from(Preset::Seed.params());
        let scene = Scene {
            physics,
            domain: TANK,
            state: state.clone(),
        };
        Painter::new(View::of(&scene), Scale::new(by, &physics, state), 600)
    }

    /// Müller's view of `TANK` with kernel radius 16 px.
    fn view() -> View {
        View {
            domain: TANK,
            radius: 8.0,
            walls: Walls::Bars,
        }
    }

    fn caption(n: usize) -> Caption {
        Caption {
            step: 300,
            time_s: 0.27,
            n,
            preset: Preset::Seed,
        }
    }

    #[test]
    fn the_caption_names_step_time_count_and_preset() {
        assert_eq!(
            caption(1000).to_string(),
            "step 300 · t = 0.270 s · N = 1000 · seed preset"
        );
    }

    #[test]
    fn the_frame_keeps_the_tank_aspect_ratio_and_its_set_width() {
        let l = Layout::new(&view(), 600);
        assert_eq!(l.width, 600);
        let (w, h) = (l.tank.x1 - l.tank.x0, l.tank.y1 - l.tank.y0);
        assert!((f64::from(w) / f64::from(h) - 1200.0 / 900.0).abs() < 0.01);
        assert!(l.height > h + 2 * l.wall);
        assert_eq!(Layout::new(&view(), 10).width, MIN_WIDTH);
    }

    #[test]
    fn the_floor_is_at_the_bottom_and_the_left_wall_on_the_left() {
        let l = Layout::new(&view(), 600);
        let (x, y) = l.to_image(0.0, 0.0);
        assert_eq!((x, y), (f64::from(l.tank.x0), f64::from(l.tank.y1)));
        let (x, y) = l.to_image(1200.0, 900.0);
        assert!((x - f64::from(l.tank.x1)).abs() < 1e-9);
        assert!((y - f64::from(l.tank.y0)).abs() < 1e-9);
    }

    #[test]
    fn a_particle_near_the_floor_is_drawn_low_in_the_tank_in_its_colour() {
        // One fast particle near the floor on the left, one at rest near the ceiling.
        let state = State::from_kinematics(
            vec![100.0, 1100.0],
            vec![20.0, 880.0],
            vec![1e9, 0.0],
            vec![0.0, 0.0],
        );
        let p = painter(ColorBy::Speed, &state);
        let img = p.draw(&state, &caption(2));
        let l = p.layout();
        let at = |x: f64, y: f64| {
            let (cx, cy) = l.to_image(x, y);
            img.pixel(cx as u32, cy as u32)
        };
        assert_eq!(at(100.0, 20.0), [253, 231, 37], "fast: top of the scale");
        assert_eq!(
            at(1100.0, 880.0),
            [68, 1, 84],
            "at rest: bottom of the scale"
        );
        assert_eq!(at(600.0, 450.0), BACKGROUND);
        assert_eq!(img.pixel(l.tank.x0 - 1, l.tank.y1 - 1), WALL);
        assert_eq!(img.pixel(l.tank.x0 + 1, l.tank.y1), WALL, "floor");
    }

    #[test]
    fn every_pixel_of_a_frame_is_near_a_palette_colour() {
        let state = sph_solver::models::mueller::scene::initial_state(Preset::Seed, 200, 1);
        let p = painter(ColorBy::Density, &state);
        let img = p.draw(&state, &caption(200));
        let palette = p.palette();
        assert!(palette.len() <= 256);
        for px in img.pixels.chunks_exact(3) {
            let nearest = palette
                .iter()
                .map(|c| {
                    (0..3)
                        .map(|k| (i32::from(c[k]) - i32::from(px[k])).abs())
                        .max()
                })
                .min()
                .flatten()
                .unwrap();
            assert!(nearest <= 2, "{px:?} is {nearest} from the palette");
        }
    }

    #[test]
    fn the_caption_and_legend_are_drawn_in_text() {
        let state = State::default();
        let p = painter(ColorBy::Speed, &state);
        let img = p.draw(&state, &caption(0));
        let l = p.layout();
        let dark_above = (0..l.tank.y0 - l.wall)
            .flat_map(|y| (0..l.width).map(move |x| (x, y)))
            .filter(|&(x, y)| img.pixel(x, y)[0] < 128)
            .count();
        let dark_below = (l.tank.y1 + l.wall..l.height)
            .flat_map(|y| (0..l.width).map(move |x| (x, y)))
            .filter(|&(x, y)| img.pixel(x, y) == [0, 0, 0])
            .count();
        assert!(dark_above > 100, "caption: {dark_above} dark pixels");
        assert!(dark_below > 20, "legend labels: {dark_below} black pixels");
    }

    /// The `wcsph` dam break at resolution 8 (128 fluid particles) and its painter.
    fn wcsph(by: ColorBy) -> (Scene, Painter) {
        let scene = Scene::tank(sph_solver::models::wcsph::scene::Fill::DamBreak, 8).unwrap();
        let view = View::of(&scene);
        let scale = Scale::new(by, &scene.physics, &scene.state);
        let painter = Painter::new(view, scale, 600);
        (scene, painter)
    }

    #[test]
    fn a_wcsph_caption_shows_the_simulated_time_and_the_fluid_particles() {
        let (scene, _) = wcsph(ColorBy::Speed);
        let caption = Caption::new(&scene.physics, 40, 0.0261, scene.state.len());
        assert_eq!(
            caption.to_string(),
            "step 40 · t = 0.026 s · N = 128 · wcsph preset"
        );
        // Müller's time stays step · DT whatever the sum of the steps says.
        let seed = Physics::from(Preset::Seed.params());
        assert_eq!(Caption::new(&seed, 300, 99.0, 1000), caption_of_seed());
    }

    fn caption_of_seed() -> Caption {
        Caption {
            step: 300,
            time_s: 300.0 * Preset::Seed.params().dt,
            n: 1000,
            preset: Preset::Seed,
        }
    }

    #[test]
    fn the_wcsph_frame_holds_the_walls_and_its_axes_are_in_metres() {
        let (scene, p) = wcsph(ColorBy::Speed);
        let l = p.layout();
        let Walls::Particles { thickness, .. } = View::of(&scene).walls else {
            panic!("wcsph walls are particles");
        };
        assert_eq!(thickness, 3.0 * 0.125);
        // The drawn area's corners are the walls' outer corners and the top of the walls.
        let (x, y) = l.to_image(-thickness, -thickness);
        assert!((x - f64::from(l.tank.x0)).abs() < 1e-9 && (y - f64::from(l.tank.y1)).abs() < 0.5);
        let (x, y) = l.to_image(5.0 + thickness, 2.5);
        assert!((x - f64::from(l.tank.x1)).abs() < 1e-9 && (y - f64::from(l.tank.y0)).abs() < 1e-9);
        // Every particle, walls included, lies inside the drawn area.
        for i in 0..scene.state.len() {
            let (x, y) = l.to_image(scene.state.x[i], scene.state.y[i]);
            assert!(x > f64::from(l.tank.x0) && x < f64::from(l.tank.x1), "{i}");
            assert!(y > f64::from(l.tank.y0) && y < f64::from(l.tank.y1), "{i}");
        }
        // Neighbours at dx touch: the radius is dx/2.
        assert!((l.radius - 0.5 * 0.125 * l.zoom).abs() < 1e-12);
        let axes = l.axes.expect("wcsph frames have axes");
        let labels = |ticks: Vec<(f64, String)>| ticks.into_iter().map(|t| t.1).collect::<Vec<_>>();
        assert_eq!(labels(axes.x_ticks()), ["0", "1", "2", "3", "4", "5 m"]);
        assert_eq!(labels(axes.y_ticks()), ["0", "1", "2 m"]);
        assert_eq!(l.wall, 0);
    }

    #[test]
    fn wcsph_particles_are_coloured_by_speed_in_metres_per_second_and_walls_grey() {
        let (mut scene, p) = wcsph(ColorBy::Speed);
        let fluid = scene.fluid();
        scene.state.vx[0] = 6.3; // the top of the scale
        scene.state.vy[1] = -3.13; // half way
        let s = &scene.state;
        assert_eq!(p.color(s, 0), [253, 231, 37], "fast");
        assert_eq!(p.color(s, 2), [68, 1, 84], "still");
        assert_ne!(p.color(s, 1), p.color(s, 0));
        assert_ne!(p.color(s, 1), p.color(s, 2));
        assert_eq!(p.color(s, fluid), WALL_PARTICLE);
        assert_eq!(p.color(s, s.len() - 1), WALL_PARTICLE);
        // And so they are drawn: the fast particle in yellow, a wall particle in grey.
        let img = p.draw(s, &Caption::new(&scene.physics, 0, 0.0, s.len()));
        let at = |i: usize| {
            let (x, y) = p.layout().to_image(s.x[i], s.y[i]);
            img.pixel(x as u32, y as u32)
        };
        assert_eq!(at(0), [253, 231, 37]);
        assert_eq!(at(2), [68, 1, 84]);
        assert_eq!(at(s.len() - 1), WALL_PARTICLE);
        assert!(p.palette().contains(&WALL_PARTICLE));
    }

    #[test]
    fn a_wcsph_frame_draws_axis_labels_below_and_left_of_the_tank() {
        let (scene, p) = wcsph(ColorBy::Density);
        let img = p.draw(
            &scene.state,
            &Caption::new(&scene.physics, 0, 0.0, scene.state.len()),
        );
        let l = p.layout();
        let dark = |xs: std::ops::Range<u32>, ys: std::ops::Range<u32>| {
            ys.flat_map(|y| xs.clone().map(move |x| (x, y)))
                .filter(|&(x, y)| img.pixel(x, y)[0] < 128)
                .count()
        };
        assert!(dark(0..l.tank.x0, l.tank.y0..l.tank.y1) > 30, "y labels");
        assert!(dark(0..l.width, l.tank.y1..l.legend_top) > 60, "x labels");
        assert!(dark(0..l.width, l.legend_top..l.height) > 60, "legend");
    }
}
