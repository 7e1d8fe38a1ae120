//! Animations of the dam break, to see that the solver behaves like a fluid (the seed
//! program's OpenGL window, headless).
//!
//! The pipeline follows the data: a [`frame::Painter`] turns a particle state into an
//! [`image::Image`] (pure: state → pixels), and an [`output::Output`] writes the images as
//! an animated GIF ([`gif_writer`]) or numbered PNG files ([`png_frames`]).
//! [`scale`] decides what a particle's colour shows and [`colormap`] which colour that is;
//! [`text`] writes the caption and legend in the bundled font.

pub mod colormap;
pub mod frame;
pub mod gif_writer;
pub mod image;
pub mod output;
pub mod png_frames;
pub mod scale;
pub mod text;
