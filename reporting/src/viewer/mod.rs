//! `bench-sph view` (cargo feature `viewer`): the dam break live in a window, as the seed
//! program showed it in OpenGL. Space pauses, r resets, + and - double and halve N, s moves
//! to the next strategy, c switches the colour between speed and density, q or Esc quits.
//!
//! The window is minifb's; on Linux it loads the X11 libraries when it opens, so building
//! needs no system package and a machine without a display gets a clear error.

pub mod scene;
mod stepper;

use anyhow::Context;
use minifb::{Key, KeyRepeat, ScaleMode, Window, WindowOptions};

use crate::render::image::Image;
use scene::{Action, Scene, Settings};

/// Frames per second the window is refreshed at, at most.
const TARGET_FPS: usize = 60;

/// Opens the window and runs until it is closed.
pub fn run(settings: Settings) -> anyhow::Result<()> {
    let n = settings.n;
    let mut scene = Scene::new(settings).with_context(|| format!("no memory for {n} particles"))?;
    let first = scene.draw();
    let options = WindowOptions {
        resize: true,
        scale_mode: ScaleMode::AspectRatioStretch,
        ..WindowOptions::default()
    };
    let mut window = Window::new(
        "bench-sph: dam break",
        first.width as usize,
        first.height as usize,
        options,
    )
    .context("cannot open a window (is a display available? try the `render` command)")?;
    window.set_target_fps(TARGET_FPS);

    let mut buffer = Vec::new();
    while window.is_open() && !window.is_key_down(Key::Escape) && !window.is_key_down(Key::Q) {
        for key in window.get_keys_pressed(KeyRepeat::No) {
            if let Some(action) = action_of(key) {
                scene.apply(action);
            }
        }
        scene.advance();
        let img = scene.draw();
        to_0rgb(&img, &mut buffer);
        window
            .update_with_buffer(&buffer, img.width as usize, img.height as usize)
            .context("cannot draw in the window")?;
    }
    Ok(())
}

/// The action a key stands for, if any.
fn action_of(key: Key) -> Option<Action> {
    match key {
        Key::Space => Some(Action::TogglePause),
        Key::R => Some(Action::Reset),
        Key::Equal | Key::NumPadPlus => Some(Action::MoreParticles),
        Key::Minus | Key::NumPadMinus => Some(Action::FewerParticles),
        Key::S => Some(Action::NextStrategy),
        Key::C => Some(Action::NextColor),
        _ => None,
    }
}

/// `img` as minifb's pixels: one `0x00RRGGBB` word per pixel.
fn to_0rgb(img: &Image, out: &mut Vec<u32>) {
    out.clear();
    out.extend(
        img.pixels
            .chunks_exact(3)
            .map(|p| u32::from_be_bytes([0, p[0], p[1], p[2]])),
    );
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pixels_become_0rgb_words() {
        let img = Image {
            width: 2,
            height: 1,
            pixels: vec![0x12, 0x34, 0x56, 255, 0, 1],
        };
        let mut out = vec![7];
        to_0rgb(&img, &mut out);
        assert_eq!(out, [0x0012_3456, 0x00ff_0001]);
    }

    #[test]
    fn every_action_has_a_key() {
        let keys = [Key::Space, Key::R, Key::Equal, Key::Minus, Key::S, Key::C];
        let actions: Vec<_> = keys.into_iter().filter_map(action_of).collect();
        assert_eq!(actions.len(), 6);
        assert_eq!(action_of(Key::Z), None);
    }
}
