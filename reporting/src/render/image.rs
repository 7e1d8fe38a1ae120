//! An RGB raster and the two shapes frames are made of: rectangles and discs.

/// An RGB image, 8 bits per channel, rows from the top, `3 · width · height` bytes.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Image {
    /// Width, px.
    pub width: u32,
    /// Height, px.
    pub height: u32,
    /// Row-major RGB bytes, top row first.
    pub pixels: Vec<u8>,
}

/// An axis-aligned rectangle of pixels: columns `x0..x1`, rows `y0..y1` (ends excluded).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Rect {
    /// First column.
    pub x0: u32,
    /// First row.
    pub y0: u32,
    /// One past the last column.
    pub x1: u32,
    /// One past the last row.
    pub y1: u32,
}

impl Image {
    /// A `width × height` image of one colour.
    pub fn filled(width: u32, height: u32, color: [u8; 3]) -> Image {
        let pixels = color.repeat(width as usize * height as usize);
        Image {
            width,
            height,
            pixels,
        }
    }

    /// The colour at column `x`, row `y`.
    ///
    /// # Panics
    /// If the pixel is outside the image.
    pub fn pixel(&self, x: u32, y: u32) -> [u8; 3] {
        assert!(x < self.width && y < self.height, "({x}, {y}) is outside");
        let at = 3 * (y as usize * self.width as usize + x as usize);
        [self.pixels[at], self.pixels[at + 1], self.pixels[at + 2]]
    }

    /// Paints `rect` (clipped to the image) in `color`.
    pub fn fill_rect(&mut self, rect: Rect, color: [u8; 3]) {
        let (x1, y1) = (rect.x1.min(self.width), rect.y1.min(self.height));
        if rect.x0 >= x1 {
            return;
        }
        let stride = 3 * self.width as usize;
        for y in rect.y0..y1 {
            let row = y as usize * stride;
            let span = &mut self.pixels[row + 3 * rect.x0 as usize..row + 3 * x1 as usize];
            for px in span.chunks_exact_mut(3) {
                px.copy_from_slice(&color);
            }
        }
    }

    /// Paints the pixels whose centres lie within `radius` of (`cx`, `cy`) (image coordinates,
    /// px, y down), and always the pixel holding the centre, clipped to `clip`.
    pub fn fill_disc(&mut self, cx: f64, cy: f64, radius: f64, clip: Rect, color: [u8; 3]) {
        let span = |c: f64, lo: u32, hi: u32| {
            let first = (c - radius).floor().max(f64::from(lo)) as u32;
            let last = ((c + radius).ceil().min(f64::from(hi)) as u32).max(first);
            first..last
        };
        let (x1, y1) = (clip.x1.min(self.width), clip.y1.min(self.height));
        let centre = (cx.floor(), cy.floor());
        let r2 = radius * radius;
        for y in span(cy, clip.y0, y1) {
            let dy = f64::from(y) + 0.5 - cy;
            for x in span(cx, clip.x0, x1) {
                let dx = f64::from(x) + 0.5 - cx;
                if dx * dx + dy * dy <= r2 || (f64::from(x), f64::from(y)) == centre {
                    let at = 3 * (y as usize * self.width as usize + x as usize);
                    self.pixels[at..at + 3].copy_from_slice(&color);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const WHITE: [u8; 3] = [255; 3];
    const RED: [u8; 3] = [255, 0, 0];

    fn whole(img: &Image) -> Rect {
        Rect {
            x0: 0,
            y0: 0,
            x1: img.width,
            y1: img.height,
        }
    }

    fn count(img: &Image, color: [u8; 3]) -> usize {
        img.pixels.chunks_exact(3).filter(|p| *p == color).count()
    }

    #[test]
    fn a_disc_covers_about_its_area_and_is_centred() {
        let mut img = Image::filled(40, 40, WHITE);
        img.fill_disc(20.0, 20.0, 5.0, whole(&img), RED);
        let area = count(&img, RED) as f64;
        assert!((area - 25.0 * std::f64::consts::PI).abs() < 8.0, "{area}");
        assert_eq!(img.pixel(20, 20), RED);
        assert_eq!(img.pixel(24, 20), RED);
        assert_eq!(img.pixel(14, 20), WHITE);
        assert_eq!(img.pixel(20, 26), WHITE);
    }

    #[test]
    fn a_tiny_disc_still_paints_the_pixel_holding_its_centre() {
        let mut img = Image::filled(4, 4, WHITE);
        img.fill_disc(2.9, 1.1, 0.1, whole(&img), RED);
        assert_eq!(count(&img, RED), 1);
        assert_eq!(img.pixel(2, 1), RED);
    }

    #[test]
    fn shapes_are_clipped_and_never_write_outside() {
        let mut img = Image::filled(10, 10, WHITE);
        let clip = Rect {
            x0: 2,
            y0: 2,
            x1: 8,
            y1: 8,
        };
        // A disc around the corner (0, 0): only its part inside the clip is painted.
        img.fill_disc(0.0, 0.0, 6.0, clip, RED);
        let in_clip_and_radius = (2..8u32)
            .flat_map(|x| (2..8u32).map(move |y| (f64::from(x) + 0.5, f64::from(y) + 0.5)))
            .filter(|(x, y)| x * x + y * y <= 36.0)
            .count();
        assert_eq!(count(&img, RED), in_clip_and_radius);
        assert_eq!(img.pixel(1, 1), WHITE);
        assert_eq!(img.pixel(2, 2), RED);

        // Far outside: nothing. A rectangle past the edge: only the part inside.
        img.fill_disc(-50.0, 300.0, 3.0, clip, RED);
        let corner = Rect {
            x0: 9,
            y0: 9,
            x1: 20,
            y1: 20,
        };
        img.fill_rect(corner, RED);
        assert_eq!(count(&img, RED), in_clip_and_radius + 1);
        assert_eq!(img.pixel(9, 9), RED);
    }
}
