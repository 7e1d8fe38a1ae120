//! Text on an [`Image`], in the bundled DejaVu Sans (see `assets/fonts/DejaVuSans-LICENSE.txt`;
//! no system font is ever looked up).
//!
//! Frames lay out text here with `ab_glyph` rather than through plotters, whose `ab_glyph`
//! backend (0.3.7) draws every glyph at the pen position without its left side bearing: the
//! narrow "1" then sits at the left of its cell and "1000" reads as "1 000".

use std::sync::OnceLock;

use ab_glyph::{Font, FontRef, PxScale, ScaleFont, point};

use crate::plot::font::BYTES as FONT_BYTES;
use crate::render::image::Image;

/// The bundled font, parsed once.
fn font() -> &'static FontRef<'static> {
    static FONT: OnceLock<FontRef<'static>> = OnceLock::new();
    FONT.get_or_init(|| {
        FontRef::try_from_slice(FONT_BYTES).expect("the bundled font is a valid TrueType file")
    })
}

/// How far the pen moves over `text` at `size` px (advances and kerning), px.
pub fn width(text: &str, size: f64) -> f64 {
    let font = font().as_scaled(PxScale::from(size as f32));
    let mut pen = 0.0;
    let mut previous = None;
    for c in text.chars() {
        let id = font.glyph_id(c);
        if let Some(p) = previous {
            pen += font.kern(p, id);
        }
        pen += font.h_advance(id);
        previous = Some(id);
    }
    f64::from(pen)
}

/// Height of a capital letter above the baseline at `size` px, px.
pub fn cap_height(size: f64) -> f64 {
    let font = font();
    let scaled = font.as_scaled(PxScale::from(size as f32));
    let glyph = scaled.scaled_glyph('H');
    font.outline_glyph(glyph)
        .map_or(0.7 * size, |g| -f64::from(g.px_bounds().min.y))
}

/// Draws `text` at `size` px in `color`, starting at `x` on the baseline `baseline` (image
/// px, y down), blending each pixel by the glyph's coverage. Pixels off the image are skipped.
pub fn draw(img: &mut Image, text: &str, (x, baseline): (f64, f64), size: f64, color: [u8; 3]) {
    let font = font();
    let scale = PxScale::from(size as f32);
    let scaled = font.as_scaled(scale);
    let mut pen = x as f32;
    let mut previous = None;
    for c in text.chars() {
        let id = scaled.glyph_id(c);
        if let Some(p) = previous {
            pen += scaled.kern(p, id);
        }
        previous = Some(id);
        let glyph = id.with_scale_and_position(scale, point(pen, baseline as f32));
        pen += scaled.h_advance(id);
        let Some(outline) = font.outline_glyph(glyph) else {
            continue; // a space
        };
        let bounds = outline.px_bounds();
        outline.draw(|gx, gy, coverage| {
            let px = bounds.min.x as i64 + i64::from(gx);
            let py = bounds.min.y as i64 + i64::from(gy);
            if px < 0 || py < 0 || px >= i64::from(img.width) || py >= i64::from(img.height) {
                return;
            }
            let at = 3 * (py as usize * img.width as usize + px as usize);
            let a = coverage.clamp(0.0, 1.0);
            for (channel, ink) in img.pixels[at..at + 3].iter_mut().zip(color) {
                let mixed = f32::from(*channel) * (1.0 - a) + f32::from(ink) * a;
                *channel = mixed.round() as u8;
            }
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const WHITE: [u8; 3] = [255; 3];

    /// Columns holding ink, as runs (first, last) of consecutive inked columns.
    fn inked_runs(img: &Image) -> Vec<(u32, u32)> {
        let inked: Vec<bool> = (0..img.width)
            .map(|x| (0..img.height).any(|y| img.pixel(x, y)[0] < 160))
            .collect();
        let mut runs: Vec<(u32, u32)> = Vec::new();
        for (x, &ink) in inked.iter().enumerate() {
            let x = x as u32;
            match runs.last_mut() {
                Some(run) if ink && run.1 + 1 == x => run.1 = x,
                _ if ink => runs.push((x, x)),
                _ => {}
            }
        }
        runs
    }

    #[test]
    fn digits_are_evenly_spaced_including_a_one() {
        let mut img = Image::filled(120, 30, WHITE);
        draw(&mut img, "1000", (4.0, 22.0), 20.0, [0, 0, 0]);
        let runs = inked_runs(&img);
        assert_eq!(runs.len(), 4, "{runs:?}");
        let gaps: Vec<i64> = runs
            .windows(2)
            .map(|w| i64::from(w[1].0) - i64::from(w[0].1))
            .collect();
        // Without the left side bearing the gap after "1" is several pixels wider.
        let (min, max) = (gaps.iter().min().unwrap(), gaps.iter().max().unwrap());
        assert!(max - min <= 2, "gaps {gaps:?}");
    }

    #[test]
    fn black_text_on_white_is_drawn_in_greys_within_its_width() {
        let mut img = Image::filled(200, 40, WHITE);
        let w = width("step 300", 16.0);
        draw(&mut img, "step 300", (10.0, 28.0), 16.0, [0, 0, 0]);
        let runs = inked_runs(&img);
        assert!(runs.first().unwrap().0 >= 10);
        assert!(f64::from(runs.last().unwrap().1) <= 10.0 + w + 1.0);
        assert!(
            img.pixels
                .chunks_exact(3)
                .all(|p| p[0] == p[1] && p[1] == p[2])
        );
        assert!(img.pixels.chunks_exact(3).any(|p| p[0] == 0));
        assert!((cap_height(16.0) - 0.73 * 16.0).abs() < 2.0);
    }

    #[test]
    fn text_off_the_image_is_clipped() {
        let blank = Image::filled(10, 10, WHITE);
        // Starting left of the image and rising above it: the part inside is drawn.
        let mut partly = Image::filled(10, 10, WHITE);
        draw(&mut partly, "bench-sph", (-20.0, 5.0), 30.0, [0, 0, 0]);
        assert_eq!(partly.pixels.len(), blank.pixels.len());
        assert!(partly.pixels.chunks_exact(3).any(|p| p[0] < 128));
        // Wholly below the image: nothing is drawn.
        let mut below = Image::filled(10, 10, WHITE);
        draw(&mut below, "x", (8.0, 200.0), 30.0, [0, 0, 0]);
        assert_eq!(below.pixels, blank.pixels);
    }
}
