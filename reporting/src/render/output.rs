//! Where an animation's frames go: one GIF file or a folder of PNG files, opened before
//! anything is simulated so that a bad path fails at once.
//!
//! Nothing half-written is ever left at a destination: the GIF is written to a temporary file
//! and renamed over its path by [`Output::finish`] (see [`sph_harness::io::sink`]), so a
//! failed or interrupted render leaves the earlier file, or none; each PNG frame is written
//! whole the same way, and the folder is claimed ([`sph_harness::output::claim`]) so that
//! frames of an earlier, longer render are removed rather than mixed with the new ones.

use std::path::{Path, PathBuf};

use anyhow::Context;
use gif::EncodingError;

use crate::render::gif_writer::GifWriter;
use crate::render::image::Image;
use crate::render::png_frames::PngFrames;
use sph_harness::io::sink::Sink;

/// An open destination for frames.
pub enum Output {
    /// An animated GIF.
    Gif {
        /// The file.
        path: PathBuf,
        /// Its encoder.
        writer: GifWriter<Sink>,
    },
    /// Numbered PNG files.
    Frames(PngFrames),
}

/// A GIF encoder's error as one message: its I/O errors say the same thing as their source,
/// so only the source is kept.
fn flatten(err: EncodingError) -> anyhow::Error {
    match err {
        EncodingError::Io(io) => io.into(),
        other => anyhow::anyhow!("{other}"),
    }
}

impl Output {
    /// Starts the GIF file `path` for `width × height` frames drawn in `palette`, played at
    /// `fps` frames per second (GIF delays are whole centiseconds, at least 2).
    pub fn gif(
        path: &Path,
        (width, height): (u32, u32),
        palette: &[[u8; 3]],
        fps: u32,
    ) -> anyhow::Result<Output> {
        let cannot = || format!("cannot write GIF file '{}'", path.display());
        let sink = Sink::create(path)?;
        let size = |v: u32| u16::try_from(v).with_context(|| format!("{v} px is too large"));
        let delay_cs = (100.0 / f64::from(fps.max(1))).round().max(2.0) as u16;
        let writer = GifWriter::new(sink, size(width)?, size(height)?, palette, delay_cs)
            .map_err(flatten)
            .with_context(cannot)?;
        Ok(Output::Gif {
            path: path.to_owned(),
            writer,
        })
    }

    /// Claims the folder `dir` (created with its parents if missing) for PNG frames; see
    /// [`PngFrames::create`] for what it may already hold, and `force`.
    pub fn png_frames(dir: &Path, force: bool) -> anyhow::Result<Output> {
        Ok(Output::Frames(PngFrames::create(dir, force)?))
    }

    /// Adds a frame.
    pub fn push(&mut self, image: &Image) -> anyhow::Result<()> {
        match self {
            Output::Gif { path, writer } => writer
                .push(image)
                .map_err(flatten)
                .with_context(|| format!("cannot write GIF file '{}'", path.display())),
            Output::Frames(frames) => frames.push(image).map(drop),
        }
    }

    /// Completes the output: the GIF's last frame and trailer, then the rename over its
    /// path; or the removal of earlier frames this render did not write again.
    pub fn finish(self) -> anyhow::Result<()> {
        match self {
            Output::Gif { path, writer } => {
                let sink = writer
                    .finish()
                    .map_err(flatten)
                    .with_context(|| format!("cannot write GIF file '{}'", path.display()))?;
                sink.commit()
            }
            Output::Frames(frames) => frames.finish(),
        }
    }

    /// Where the frames go, for messages: `'anim.gif'` or `'dir/frame_*.png'`.
    pub fn describe(&self) -> String {
        match self {
            Output::Gif { path, .. } => format!("'{}'", path.display()),
            Output::Frames(frames) => {
                format!("'{}'", frames.dir().join("frame_*.png").display())
            }
        }
    }
}
