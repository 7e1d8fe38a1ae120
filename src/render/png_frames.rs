//! PNG frames out: one file per frame, `frame_00000.png`, `frame_00001.png`, … in a folder
//! (the numbering `ffmpeg -i frame_%05d.png` reads).

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use anyhow::Context;

use crate::render::image::Image;

/// Encodes `image` as an 8-bit RGB PNG on `out`.
pub fn write_png<W: Write>(out: W, image: &Image) -> Result<(), png::EncodingError> {
    let mut encoder = png::Encoder::new(out, image.width, image.height);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    let mut writer = encoder.write_header()?;
    writer.write_image_data(&image.pixels)?;
    writer.finish()
}

/// Numbered PNG files in one folder.
#[derive(Debug)]
pub struct PngFrames {
    dir: PathBuf,
    written: usize,
}

impl PngFrames {
    /// Frames into `dir`, created (with its parents) if missing. Files from an earlier
    /// render with more frames are left as they are.
    pub fn create(dir: &Path) -> anyhow::Result<PngFrames> {
        std::fs::create_dir_all(dir)
            .with_context(|| format!("cannot create frames folder '{}'", dir.display()))?;
        Ok(PngFrames {
            dir: dir.to_owned(),
            written: 0,
        })
    }

    /// The path the `index`-th frame (from 0) is written to.
    pub fn path_of(&self, index: usize) -> PathBuf {
        self.dir.join(format!("frame_{index:05}.png"))
    }

    /// Writes the next frame and returns its path.
    pub fn push(&mut self, image: &Image) -> anyhow::Result<PathBuf> {
        let path = self.path_of(self.written);
        let cannot = || format!("cannot write frame '{}'", path.display());
        let mut out = BufWriter::new(File::create(&path).with_context(cannot)?);
        write_png(&mut out, image).with_context(cannot)?;
        out.flush().with_context(cannot)?;
        self.written += 1;
        Ok(path)
    }

    /// Frames written so far.
    pub fn written(&self) -> usize {
        self.written
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_png_decodes_to_the_same_pixels() {
        let image = Image {
            width: 3,
            height: 2,
            pixels: (0..18).map(|v| v * 14).collect(),
        };
        let mut bytes = Vec::new();
        write_png(&mut bytes, &image).unwrap();
        let mut reader = png::Decoder::new(std::io::Cursor::new(bytes))
            .read_info()
            .unwrap();
        let mut buf = vec![0; reader.output_buffer_size().unwrap()];
        let info = reader.next_frame(&mut buf).unwrap();
        assert_eq!((info.width, info.height), (3, 2));
        assert_eq!(info.color_type, png::ColorType::Rgb);
        assert_eq!(&buf[..info.buffer_size()], &image.pixels[..]);
    }

    #[test]
    fn frames_are_numbered_from_zero_with_five_digits() {
        let dir = tempfile::tempdir().unwrap();
        let mut frames = PngFrames::create(&dir.path().join("a/b")).unwrap();
        let image = Image::filled(2, 2, [1, 2, 3]);
        let first = frames.push(&image).unwrap();
        let second = frames.push(&image).unwrap();
        assert!(first.ends_with("a/b/frame_00000.png"), "{first:?}");
        assert!(second.ends_with("a/b/frame_00001.png"), "{second:?}");
        assert!(second.is_file());
        assert_eq!(frames.written(), 2);
    }
}
