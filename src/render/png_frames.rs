//! PNG frames out: one file per frame, `frame_00000.png`, `frame_00001.png`, … in a folder
//! (the numbering `ffmpeg -i frame_%05d.png` reads). Each frame is written whole (temporary
//! file, then rename), and the folder is claimed ([`crate::output::claim`]): files named like
//! frames are this command's own, anything else makes it refuse the folder unless `--force`.

use std::io::Write;
use std::path::{Path, PathBuf};

use anyhow::Context;

use crate::output::atomic;
use crate::output::claim::{self, Claimed, Owner};
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

/// The name of the `index`-th frame (from 0).
fn frame_name(index: usize) -> String {
    format!("frame_{index:05}.png")
}

/// Whether `path` is a frame file as [`frame_name`] names them: render's own output.
fn is_frame(path: &Path) -> bool {
    let name = path.file_name().unwrap_or_default().to_string_lossy();
    let digits = name
        .strip_prefix("frame_")
        .and_then(|rest| rest.strip_suffix(".png"));
    digits.is_some_and(|d| d.len() >= 5 && d.bytes().all(|b| b.is_ascii_digit())) && path.is_file()
}

/// Numbered PNG files in one claimed folder.
#[derive(Debug)]
pub struct PngFrames {
    claimed: Claimed,
    written: Vec<PathBuf>,
}

impl PngFrames {
    /// Frames into `dir`, created (with its parents) if missing. Frames of an earlier render
    /// are replaced, and those not written again are removed by [`PngFrames::finish`]; a
    /// folder holding anything else is refused unless `force`, which writes beside it.
    pub fn create(dir: &Path, force: bool) -> anyhow::Result<PngFrames> {
        let owner = Owner {
            command: "bench-sph render",
            option: "--frames",
            owns: &is_frame,
            tolerates: &claim::nothing,
        };
        Ok(PngFrames {
            claimed: claim::claim(dir, &owner, force)?,
            written: Vec::new(),
        })
    }

    /// The folder.
    pub fn dir(&self) -> &Path {
        self.claimed.dir()
    }

    /// Writes the next frame and returns its path.
    pub fn push(&mut self, image: &Image) -> anyhow::Result<PathBuf> {
        let path = self
            .claimed
            .check_writable(&frame_name(self.written.len()))?;
        let mut bytes = Vec::new();
        write_png(&mut bytes, image)
            .with_context(|| format!("cannot write frame '{}'", path.display()))?;
        atomic::write(&path, &bytes)?;
        self.written.push(path.clone());
        Ok(path)
    }

    /// Frames written so far.
    pub fn written(&self) -> usize {
        self.written.len()
    }

    /// Removes the frames of an earlier render that this one did not write again.
    pub fn finish(self) -> anyhow::Result<()> {
        self.claimed.remove_stale(&self.written).map(drop)
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
        let mut frames = PngFrames::create(&dir.path().join("a/b"), false).unwrap();
        let image = Image::filled(2, 2, [1, 2, 3]);
        let first = frames.push(&image).unwrap();
        let second = frames.push(&image).unwrap();
        assert!(first.ends_with("a/b/frame_00000.png"), "{first:?}");
        assert!(second.ends_with("a/b/frame_00001.png"), "{second:?}");
        assert!(second.is_file());
        assert_eq!(frames.written(), 2);
    }
}

#[cfg(test)]
mod claim_tests {
    use super::*;

    #[test]
    fn only_files_named_like_frames_are_renders_own() {
        let dir = tempfile::tempdir().unwrap();
        for name in [
            "frame_00003.png",
            "frame_123456.png",
            "frame_3.png",
            "frame_0000x.png",
        ] {
            std::fs::write(dir.path().join(name), "").unwrap();
        }
        std::fs::create_dir(dir.path().join("frame_00004.png")).unwrap();
        let own: Vec<bool> = [
            "frame_00003.png",
            "frame_123456.png",
            "frame_3.png",
            "frame_0000x.png",
            "frame_00004.png",
        ]
        .iter()
        .map(|n| is_frame(&dir.path().join(n)))
        .collect();
        assert_eq!(own, [true, true, false, false, false]);
    }
}
