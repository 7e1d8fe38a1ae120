//! Animated GIF out: frames in, one fixed palette for the whole animation, looping forever.
//!
//! Every pixel is mapped to its nearest palette colour (exact for the colours a painter draws,
//! nearest for text anti-aliasing), remembered per colour so a frame costs one table look-up
//! per pixel. A fixed palette keeps colours steady from frame to frame, which per-frame
//! quantisation does not. After the first frame, pixels that did not change are written
//! transparent over the frame before (`DisposalMethod::Keep`), which compresses far better
//! (when the palette leaves a slot free for it). The last frame is held for [`HOLD_LAST_CS`]
//! before the loop restarts.

use std::collections::HashMap;
use std::io::Write;

use gif::{DisposalMethod, Encoder, EncodingError, Frame, Repeat};

use crate::render::image::Image;

/// How long the last frame stays up before the animation loops, centiseconds.
pub const HOLD_LAST_CS: u16 = 150;

/// Writes frames of one size to a GIF.
pub struct GifWriter<W: Write> {
    encoder: Encoder<W>,
    width: u16,
    height: u16,
    delay_cs: u16,
    palette: Vec<[u8; 3]>,
    nearest: HashMap<[u8; 3], u8>,
    /// The palette index meaning "as in the frame before", if the palette has room for it.
    unchanged: Option<u8>,
    /// The last frame pushed, as palette indices.
    previous: Option<Vec<u8>>,
    /// The last frame's encoding is held back until we know whether it is the last one.
    pending: Option<Vec<u8>>,
}

impl<W: Write> GifWriter<W> {
    /// Starts a `width × height` GIF on `out` whose frames show for `delay_cs` centiseconds
    /// each, drawn in `palette` (1 to 256 colours).
    ///
    /// # Panics
    /// If the palette is empty or holds more than 256 colours.
    pub fn new(
        out: W,
        width: u16,
        height: u16,
        palette: &[[u8; 3]],
        delay_cs: u16,
    ) -> Result<Self, EncodingError> {
        assert!(
            (1..=256).contains(&palette.len()),
            "a GIF palette holds 1 to 256 colours, not {}",
            palette.len()
        );
        // One more entry, never drawn, stands for "unchanged".
        let unchanged = u8::try_from(palette.len()).ok();
        let mut table = palette.to_vec();
        table.extend(unchanged.map(|_| [255, 0, 255]));
        let mut encoder = Encoder::new(out, width, height, table.as_flattened())?;
        encoder.set_repeat(Repeat::Infinite)?;
        Ok(GifWriter {
            encoder,
            width,
            height,
            delay_cs,
            palette: palette.to_vec(),
            nearest: HashMap::new(),
            unchanged,
            previous: None,
            pending: None,
        })
    }

    /// Adds a frame.
    ///
    /// # Panics
    /// If the image is not the GIF's size.
    pub fn push(&mut self, image: &Image) -> Result<(), EncodingError> {
        assert!(
            image.width == u32::from(self.width) && image.height == u32::from(self.height),
            "frame is {}×{}, the GIF {}×{}",
            image.width,
            image.height,
            self.width,
            self.height
        );
        let indices: Vec<u8> = image
            .pixels
            .chunks_exact(3)
            .map(|px| self.index_of([px[0], px[1], px[2]]))
            .collect();
        let encoded = match (&self.previous, self.unchanged) {
            (Some(before), Some(unchanged)) => indices
                .iter()
                .zip(before)
                .map(|(&now, &was)| if now == was { unchanged } else { now })
                .collect(),
            _ => indices.clone(),
        };
        self.previous = Some(indices);
        if let Some(held) = self.pending.replace(encoded) {
            self.write(held, self.delay_cs)?;
        }
        Ok(())
    }

    /// Writes the last frame and the trailer, and returns the output.
    pub fn finish(mut self) -> Result<W, EncodingError> {
        if let Some(last) = self.pending.take() {
            self.write(last, self.delay_cs.max(HOLD_LAST_CS))?;
        }
        self.encoder.into_inner()
    }

    fn write(&mut self, indices: Vec<u8>, delay_cs: u16) -> Result<(), EncodingError> {
        let mut frame =
            Frame::from_indexed_pixels(self.width, self.height, indices, self.unchanged);
        frame.delay = delay_cs;
        frame.dispose = DisposalMethod::Keep;
        self.encoder.write_frame(&frame)
    }

    fn index_of(&mut self, color: [u8; 3]) -> u8 {
        let palette = &self.palette;
        *self.nearest.entry(color).or_insert_with(|| {
            let distance = |c: &[u8; 3]| -> i32 {
                (0..3)
                    .map(|k| (i32::from(c[k]) - i32::from(color[k])).pow(2))
                    .sum()
            };
            let (best, _) = palette
                .iter()
                .enumerate()
                .min_by_key(|(_, c)| distance(c))
                .expect("the palette is not empty");
            best as u8
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const PALETTE: [[u8; 3]; 3] = [[0, 0, 0], [255, 255, 255], [200, 0, 0]];

    fn image(pixels: &[[u8; 3]]) -> Image {
        Image {
            width: pixels.len() as u32,
            height: 1,
            pixels: pixels.as_flattened().to_vec(),
        }
    }

    /// Each frame as shown (drawn over the ones before), with its delay.
    fn decode(bytes: &[u8]) -> Vec<(Vec<u8>, u16)> {
        let mut options = gif::DecodeOptions::new();
        options.set_color_output(gif::ColorOutput::RGBA);
        let mut decoder = options.read_info(bytes).unwrap();
        let mut shown = vec![0; 3 * decoder.width() as usize * decoder.height() as usize];
        let mut frames = Vec::new();
        while let Some(frame) = decoder.read_next_frame().unwrap() {
            assert_eq!(frame.dispose, DisposalMethod::Keep);
            for (px, rgba) in shown.chunks_exact_mut(3).zip(frame.buffer.chunks_exact(4)) {
                if rgba[3] != 0 {
                    px.copy_from_slice(&rgba[..3]);
                }
            }
            frames.push((shown.clone(), frame.delay));
        }
        frames
    }

    #[test]
    fn palette_colours_come_back_exactly_and_others_as_their_nearest() {
        let mut gif = GifWriter::new(Vec::new(), 4, 1, &PALETTE, 5).unwrap();
        gif.push(&image(&[
            [0, 0, 0],
            [255, 255, 255],
            [200, 0, 0],
            [190, 20, 5],
        ]))
        .unwrap();
        gif.push(&image(&[
            [250, 250, 250],
            [10, 10, 10],
            [0, 0, 0],
            [0, 0, 0],
        ]))
        .unwrap();
        let frames = decode(&gif.finish().unwrap());
        assert_eq!(frames.len(), 2);
        assert_eq!(
            frames[0].0,
            [[0, 0, 0], [255, 255, 255], [200, 0, 0], [200, 0, 0]].as_flattened()
        );
        assert_eq!(
            frames[1].0,
            [[255, 255, 255], [0, 0, 0], [0, 0, 0], [0, 0, 0]].as_flattened()
        );
    }

    #[test]
    fn frames_show_for_the_set_delay_and_the_last_one_is_held() {
        let mut gif = GifWriter::new(Vec::new(), 1, 1, &PALETTE, 5).unwrap();
        for _ in 0..3 {
            gif.push(&image(&[[0, 0, 0]])).unwrap();
        }
        let delays: Vec<u16> = decode(&gif.finish().unwrap()).iter().map(|f| f.1).collect();
        assert_eq!(delays, [5, 5, HOLD_LAST_CS]);
    }

    #[test]
    fn a_gif_without_frames_is_still_a_valid_file() {
        let gif = GifWriter::new(Vec::new(), 2, 2, &PALETTE, 5).unwrap();
        assert!(decode(&gif.finish().unwrap()).is_empty());
    }
}
