//! PNG frames out: one file per frame, `frame_00000.png`, `frame_00001.png`, … in a folder
//! (the numbering `ffmpeg -i frame_%05d.png` reads). Each frame is written whole (temporary
//! file, then rename), and the folder is claimed ([`sph_harness::output::claim`]) and held for the
//! whole render: the frames its record gives to render are this command's own, anything else
//! makes it refuse the folder unless `--force`, which writes beside it and never over it.
//!
//! Frames are recorded ahead in batches that double (16, then as many again as are written):
//! the record covers every frame before it is written, and is rewritten a logarithmic number
//! of times, not once per frame. Names recorded but never written leave the record at
//! [`PngFrames::finish`].

use std::io::Write;
use std::path::{Path, PathBuf};

use anyhow::Context;

use crate::render::image::Image;
use sph_harness::output::atomic;
use sph_harness::output::claim::{self, Claimed, Owner};
use sph_harness::output::record::Command;

/// The first batch of frames recorded ahead.
const FIRST_BATCH: usize = 16;

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

/// Numbered PNG files in one claimed folder.
#[derive(Debug)]
pub struct PngFrames {
    claimed: Claimed,
    written: Vec<PathBuf>,
    /// Frames `0..recorded` are in the folder's record.
    recorded: usize,
}

impl PngFrames {
    /// Frames into `dir`, created (with its parents) if missing. Frames of an earlier render
    /// are replaced, and those not written again are removed by [`PngFrames::finish`]; a
    /// folder holding anything else is refused unless `force`, which writes beside it.
    pub fn create(dir: &Path, force: bool) -> anyhow::Result<PngFrames> {
        let owner = Owner {
            command: Command::Render,
            option: "--frames",
            replaces: &[],
            tolerates: &[],
            tolerates_unrecorded: &claim::nothing,
            writes: &[],
        };
        Ok(PngFrames {
            claimed: claim::claim(dir, &owner, force)?,
            written: Vec::new(),
            recorded: 0,
        })
    }

    /// The folder.
    pub fn dir(&self) -> &Path {
        self.claimed.dir()
    }

    /// Writes the next frame and returns its path.
    pub fn push(&mut self, image: &Image) -> anyhow::Result<PathBuf> {
        let index = self.written.len();
        let path = self.claimed.check_writable(&frame_name(index))?;
        if index >= self.recorded {
            self.record_ahead(index)?;
        }
        let mut bytes = Vec::new();
        write_png(&mut bytes, image)
            .with_context(|| format!("cannot write frame '{}'", path.display()))?;
        atomic::write(&path, &bytes)?;
        self.written.push(path.clone());
        Ok(path)
    }

    /// Records frames from `first` on, as many as have been written (at least
    /// [`FIRST_BATCH`]), stopping before a name that may not be written (its frame then
    /// fails when it comes).
    fn record_ahead(&mut self, first: usize) -> anyhow::Result<()> {
        let batch = first.max(FIRST_BATCH);
        let names: Vec<String> = (first..first + batch)
            .map(frame_name)
            .take_while(|name| self.claimed.check_writable(name).is_ok())
            .collect();
        self.claimed.record(&names)?;
        self.recorded = first + names.len();
        Ok(())
    }

    /// Frames written so far.
    pub fn written(&self) -> usize {
        self.written.len()
    }

    /// Removes the frames of an earlier render that this one did not write again, and
    /// takes the frames recorded ahead but not written out of the record.
    pub fn finish(mut self) -> anyhow::Result<()> {
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
    use sph_harness::output::record::Record;

    #[test]
    fn frames_are_recorded_ahead_and_those_not_written_are_forgotten() {
        let dir = tempfile::tempdir().unwrap();
        let mut frames = PngFrames::create(dir.path(), false).unwrap();
        let image = Image::filled(2, 2, [1, 2, 3]);
        for _ in 0..20 {
            frames.push(&image).unwrap();
        }
        let record = Record::read(dir.path()).unwrap().unwrap();
        assert_eq!(record.files.len(), 32, "16, then 16 more at frame 16");
        frames.finish().unwrap();
        let record = Record::read(dir.path()).unwrap().unwrap();
        assert_eq!(record.files.len(), 20);
        assert_eq!(record.writer("frame_00019.png"), Some(Command::Render));
    }

    #[test]
    fn a_users_file_named_like_a_frame_is_never_replaced() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("frame_00001.png"), "mine").unwrap();
        assert!(PngFrames::create(dir.path(), false).is_err());
        let mut frames = PngFrames::create(dir.path(), true).unwrap();
        let image = Image::filled(2, 2, [1, 2, 3]);
        frames.push(&image).unwrap();
        let err = frames.push(&image).unwrap_err().to_string();
        assert!(err.contains("was not written by bench-sph render"), "{err}");
        assert_eq!(
            std::fs::read_to_string(dir.path().join("frame_00001.png")).unwrap(),
            "mine"
        );
    }
}
