//! Where an animation's frames go: one GIF file or a folder of PNG files. The file or folder
//! is created when the output is opened, so a bad path fails before anything is simulated.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use anyhow::Context;

use crate::render::gif_writer::GifWriter;
use crate::render::image::Image;
use crate::render::png_frames::PngFrames;

/// An open destination for frames.
pub enum Output {
    /// An animated GIF.
    Gif {
        /// The file.
        path: PathBuf,
        /// Its encoder.
        writer: GifWriter<BufWriter<File>>,
    },
    /// Numbered PNG files.
    Frames(PngFrames),
}

impl Output {
    /// Creates the GIF file `path` for `width × height` frames drawn in `palette`, played at
    /// `fps` frames per second (GIF delays are whole centiseconds, at least 2).
    pub fn gif(
        path: &Path,
        (width, height): (u32, u32),
        palette: &[[u8; 3]],
        fps: u32,
    ) -> anyhow::Result<Output> {
        let cannot = || format!("cannot write GIF file '{}'", path.display());
        let file = File::create(path).with_context(cannot)?;
        let size = |v: u32| u16::try_from(v).with_context(|| format!("{v} px is too large"));
        let delay_cs = (100.0 / f64::from(fps.max(1))).round().max(2.0) as u16;
        let writer = GifWriter::new(
            BufWriter::new(file),
            size(width)?,
            size(height)?,
            palette,
            delay_cs,
        )
        .with_context(cannot)?;
        Ok(Output::Gif {
            path: path.to_owned(),
            writer,
        })
    }

    /// Creates the folder `dir` (and its parents) for PNG frames.
    pub fn png_frames(dir: &Path) -> anyhow::Result<Output> {
        Ok(Output::Frames(PngFrames::create(dir)?))
    }

    /// Adds a frame.
    pub fn push(&mut self, image: &Image) -> anyhow::Result<()> {
        match self {
            Output::Gif { path, writer } => writer
                .push(image)
                .with_context(|| format!("cannot write GIF file '{}'", path.display())),
            Output::Frames(frames) => frames.push(image).map(drop),
        }
    }

    /// Completes the file (the GIF's last frame and trailer) and flushes it.
    pub fn finish(self) -> anyhow::Result<()> {
        match self {
            Output::Gif { path, writer } => {
                let cannot = || format!("cannot write GIF file '{}'", path.display());
                writer
                    .finish()
                    .with_context(cannot)?
                    .flush()
                    .with_context(cannot)
            }
            Output::Frames(_) => Ok(()),
        }
    }

    /// Where the frames go, for messages: `'anim.gif'` or `'dir/frame_*.png'`.
    pub fn describe(&self) -> String {
        match self {
            Output::Gif { path, .. } => format!("'{}'", path.display()),
            Output::Frames(frames) => {
                let first = frames.path_of(0);
                let dir = first.parent().unwrap_or(Path::new("."));
                format!("'{}'", dir.join("frame_*.png").display())
            }
        }
    }
}
