//! The bundled font (DejaVu Sans, see `assets/fonts/DejaVuSans-LICENSE.txt`), the one copy in
//! the binary: registered with plotters for the charts, and laid out by `render::text` for the
//! animations, so that text renders on a machine without any system font packages.

use std::sync::OnceLock;

use plotters::style::{FontStyle, register_font};

/// The font family name to use in every `TextStyle`/`("sans-serif", size)`.
pub const FAMILY: &str = "sans-serif";

/// The font file's bytes (TrueType).
pub static BYTES: &[u8] = include_bytes!("../../../assets/fonts/DejaVuSans.ttf");

/// Registers the bundled font for [`FAMILY`] (normal and bold) once per process.
/// Call it before drawing any text.
pub fn ensure_registered() -> anyhow::Result<()> {
    static DONE: OnceLock<Result<(), String>> = OnceLock::new();
    DONE.get_or_init(|| {
        for style in [FontStyle::Normal, FontStyle::Bold] {
            register_font(FAMILY, style, BYTES)
                .map_err(|_| "the bundled font could not be parsed".to_owned())?;
        }
        Ok(())
    })
    .clone()
    .map_err(anyhow::Error::msg)
}
