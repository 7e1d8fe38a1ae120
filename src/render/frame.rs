//! One frame of an animation: a particle state → an RGB image. Pure: no I/O, no clock.
//!
//! ```text
//!  step 300 · t = 0.270 s · N = 1000 · seed preset        ← caption
//! ┏━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━┓
//! ┃  ●●●                                                ┃  ← the tank, y up, walls drawn
//! ┃ ●●●●●●●                                             ┃    around its inside; particles
//! ┃●●●●●●●●●●●●●●                                       ┃    are discs of radius H/2
//! ┗━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━━┛
//!  speed, px/s   0 ▕██████████████▏ 14222                 ← legend: the colour scale
//! ```
//!
//! The image width is chosen; the tank fills it less the margins and its height follows the
//! tank's aspect ratio, so a frame is `width × height(width, tank)` for the whole animation.

use std::fmt;

use crate::render::colormap::Colormap;
use crate::render::image::{Image, Rect};
use crate::render::scale::Scale;
use crate::render::text;
use crate::sph::params::Preset;
use crate::sph::state::{Domain, State};

/// Narrowest frame, px: the caption and the legend need this much.
pub const MIN_WIDTH: u32 = 360;
/// Widest frame, px (GIF sizes are 16-bit; this also bounds memory).
pub const MAX_WIDTH: u32 = 4096;

const BACKGROUND: [u8; 3] = [255, 255, 255];
const WALL: [u8; 3] = [64, 64, 64];
const TEXT: [u8; 3] = [0, 0, 0];

/// What a frame's caption says.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Caption {
    /// Steps completed.
    pub step: usize,
    /// Simulated time, s (`step · DT`).
    pub time_s: f64,
    /// Number of particles.
    pub n: usize,
    /// The constants in use.
    pub preset: Preset,
}

impl Caption {
    /// The caption after `step` steps of `n` particles on `preset`.
    pub fn at(step: usize, n: usize, preset: Preset) -> Caption {
        Caption {
            step,
            time_s: step as f64 * preset.params().dt,
            n,
            preset,
        }
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

/// Where things go in a frame, px (image coordinates: x right, y down).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Layout {
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// The inside of the tank: the domain's [0, width] × [0, height], y flipped.
    pub tank: Rect,
    /// Wall thickness, drawn outside `tank`.
    pub wall: u32,
    /// Image px per domain px.
    pub zoom: f64,
    /// Particle radius (H/2 in the domain).
    pub radius: f64,
    /// Text height.
    pub font_px: f64,
    /// Height of the domain, domain px (to flip y).
    domain_height: f64,
}

impl Layout {
    /// The layout of a `width`-px frame of `domain` with kernel radius `h` (domain px).
    /// `width` is clamped to [`MIN_WIDTH`, `MAX_WIDTH`].
    pub fn new(domain: Domain, h: f64, width: u32) -> Layout {
        let width = width.clamp(MIN_WIDTH, MAX_WIDTH);
        let font_px = (f64::from(width) / 40.0).max(11.0);
        let margin = (font_px * 0.8).round() as u32;
        let wall = (width / 200).max(2);
        let caption_band = (font_px * 2.0).round() as u32;
        let legend_band = (font_px * 2.4).round() as u32;

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
        Layout {
            width,
            height: tank.y1 + wall + legend_band,
            tank,
            wall,
            zoom,
            radius: 0.5 * h * zoom,
            font_px,
            domain_height: domain.height,
        }
    }

    /// Where the domain point (`x`, `y`) lands in the image (y up in the domain, down here).
    pub fn to_image(&self, x: f64, y: f64) -> (f64, f64) {
        (
            f64::from(self.tank.x0) + x * self.zoom,
            f64::from(self.tank.y0) + (self.domain_height - y) * self.zoom,
        )
    }
}

/// Draws frames of one animation: a layout, a colour scale and a colour map.
#[derive(Debug, Clone)]
pub struct Painter {
    layout: Layout,
    scale: Scale,
    colormap: Colormap,
}

impl Painter {
    /// A painter for `width`-px frames of `domain` (kernel radius `h`), colouring by `scale`.
    pub fn new(domain: Domain, h: f64, scale: Scale, width: u32) -> Painter {
        Painter {
            layout: Layout::new(domain, h, width),
            scale,
            colormap: Colormap::viridis(),
        }
    }

    /// Where things go.
    pub fn layout(&self) -> &Layout {
        &self.layout
    }

    /// Every colour a frame is made of: the colour map, then 65 greys from black to white
    /// (background, walls, and the shades of anti-aliased black text on white).
    pub fn palette(&self) -> Vec<[u8; 3]> {
        let greys = (0..=64u32).map(|k| [(k * 4).min(255) as u8; 3]);
        self.colormap
            .colors()
            .iter()
            .copied()
            .chain(greys)
            .collect()
    }

    /// The frame showing `state`, captioned `caption`.
    pub fn draw(&self, state: &State, caption: &Caption) -> Image {
        let l = &self.layout;
        let mut img = Image::filled(l.width, l.height, BACKGROUND);
        let t = l.tank;
        let walls = Rect {
            x0: t.x0 - l.wall,
            y0: t.y0 - l.wall,
            x1: t.x1 + l.wall,
            y1: t.y1 + l.wall,
        };
        img.fill_rect(walls, WALL);
        img.fill_rect(t, BACKGROUND);
        for i in 0..state.len() {
            let (cx, cy) = l.to_image(state.x[i], state.y[i]);
            let color = self
                .colormap
                .color(self.scale.fraction(self.scale.value(state, i)));
            img.fill_disc(cx, cy, l.radius, t, color);
        }
        self.draw_caption(&mut img, &caption.to_string());
        self.draw_legend(&mut img);
        img
    }

    /// The caption, centred vertically in the band above the tank.
    fn draw_caption(&self, img: &mut Image, caption: &str) {
        let l = &self.layout;
        let band = f64::from(l.tank.y0 - l.wall);
        let baseline = (band + text::cap_height(l.font_px)) / 2.0;
        text::draw(
            img,
            caption,
            (f64::from(l.tank.x0), baseline),
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
        let mid = f64::from(l.tank.y1 + l.wall + l.height) / 2.0;
        let baseline = mid + text::cap_height(em) / 2.0;

        let title_x = f64::from(l.tank.x0);
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
        let params = Preset::Seed.params();
        Painter::new(TANK, params.h, Scale::new(by, &params, state), 600)
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
        let l = Layout::new(TANK, 16.0, 600);
        assert_eq!(l.width, 600);
        let (w, h) = (l.tank.x1 - l.tank.x0, l.tank.y1 - l.tank.y0);
        assert!((f64::from(w) / f64::from(h) - 1200.0 / 900.0).abs() < 0.01);
        assert!(l.height > h + 2 * l.wall);
        assert_eq!(Layout::new(TANK, 16.0, 10).width, MIN_WIDTH);
    }

    #[test]
    fn the_floor_is_at_the_bottom_and_the_left_wall_on_the_left() {
        let l = Layout::new(TANK, 16.0, 600);
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
        let state = crate::scene::dam_break::initial_state(Preset::Seed, 200, 1);
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
}
