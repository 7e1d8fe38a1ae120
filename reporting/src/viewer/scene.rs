//! What the viewer shows and how keys change it, without a window: a simulation, the painter
//! for its tank, and the settings the keys cycle through.

use std::collections::TryReserveError;

use sph_strategies::{Config, StrategyName};

use crate::render::frame::{Caption, Painter, View};
use crate::render::image::Image;
use crate::render::scale::{ColorBy, Scale};
use crate::render::text;
use crate::viewer::stepper::Stepper;
use sph_solver::models::Physics;
use sph_solver::models::Preset;
use sph_solver::scene::Scene as DamBreak;
use sph_solver::sph::neighbors::NeighborMode;

/// Fewest and most particles `+`/`-` reach.
pub const N_RANGE: (usize, usize) = (10, 1_000_000);

/// The viewer's settings: the keys change some of them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Settings {
    /// Constants and integration order.
    pub preset: Preset,
    /// Number of particles (`+` doubles, `-` halves); for `wcsph`, the fluid particles: the
    /// resolution whose dam break has the nearest count is used.
    pub n: usize,
    /// Seed of the initial jitter.
    pub seed: u64,
    /// Neighbour search.
    pub neighbors: NeighborMode,
    /// Strategy (`s` moves to the next in the registry).
    pub strategy: StrategyName,
    /// Threads and chunks for the strategy.
    pub config: Config,
    /// Steps between two frames on screen.
    pub every: usize,
    /// What the colour shows (`c` switches).
    pub color: ColorBy,
    /// Frame width, px.
    pub width: u32,
}

/// What a key asks for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Action {
    /// Pause or resume.
    TogglePause,
    /// Back to the initial state.
    Reset,
    /// Twice the particles (rebuilds the scene).
    MoreParticles,
    /// Half the particles (rebuilds the scene).
    FewerParticles,
    /// The next strategy in the registry.
    NextStrategy,
    /// Colour by the other quantity.
    NextColor,
}

/// The running simulation and everything needed to draw it.
pub struct Scene {
    settings: Settings,
    sim: Stepper,
    looks: Looks,
    painter: Painter,
    paused: bool,
    /// Steps per second of the last advance, wall clock.
    rate: Option<f64>,
    /// Why the simulation stopped, if it did.
    failure: Option<String>,
}

impl Scene {
    /// The dam break of `settings`, at step 0, running; an error if there is no memory for it.
    pub fn new(settings: Settings) -> Result<Scene, TryReserveError> {
        let (sim, looks) = build(&settings)?;
        Ok(Scene {
            painter: looks.painter(&settings),
            settings,
            sim,
            looks,
            paused: false,
            rate: None,
            failure: None,
        })
    }

    /// The settings now.
    pub fn settings(&self) -> &Settings {
        &self.settings
    }

    /// Steps completed since the last reset.
    pub fn steps_done(&self) -> usize {
        self.sim.shown().1
    }

    /// Whether the simulation is paused (by the user or by a failure).
    pub fn paused(&self) -> bool {
        self.paused || self.failure.is_some()
    }

    /// Applies a key's action.
    pub fn apply(&mut self, action: Action) {
        let s = &mut self.settings;
        match action {
            Action::TogglePause => self.paused = !self.paused,
            Action::Reset => {}
            Action::MoreParticles => s.n = (s.n * 2).min(N_RANGE.1),
            Action::FewerParticles => s.n = (s.n / 2).max(N_RANGE.0),
            Action::NextStrategy => {
                let all = StrategyName::ALL;
                let at = all.iter().position(|&x| x == s.strategy).unwrap_or(0);
                s.strategy = all[(at + 1) % all.len()];
                self.sim.switch_to(s.strategy);
                return; // the simulation goes on with the new strategy
            }
            Action::NextColor => {
                s.color = match s.color {
                    ColorBy::Speed => ColorBy::Density,
                    ColorBy::Density => ColorBy::Speed,
                };
                self.painter = self.looks.painter(s);
                return;
            }
        }
        if action != Action::TogglePause {
            match build(&self.settings) {
                Ok((sim, looks)) => {
                    self.painter = looks.painter(&self.settings);
                    (self.sim, self.looks) = (sim, looks);
                    (self.rate, self.failure) = (None, None);
                }
                Err(err) => {
                    let n = self.settings.n;
                    self.failure = Some(format!("no memory for N = {n} ({err}): press -"));
                }
            }
        }
    }

    /// Runs the next `every` steps unless paused. A failing step pauses the scene for good
    /// (until a reset) and its message is shown.
    pub fn advance(&mut self) {
        if self.paused() {
            return;
        }
        match self.sim.advance() {
            Ok(wall_s) => self.rate = Some(self.settings.every as f64 / wall_s.max(1e-9)),
            Err(err) => self.failure = Some(format!("{err}: press r to reset")),
        }
    }

    /// The frame on screen: the rendered state with two status lines below it.
    pub fn draw(&self) -> Image {
        let (state, step) = self.sim.shown();
        let caption = Caption::new(
            &self.looks.physics,
            step,
            self.sim.shown_time_s(),
            state.len(),
        );
        let frame = self.painter.draw(state, &caption);
        let em = self.painter.layout().font_px;
        let line = (1.5 * em).round() as u32;
        let mut img = Image::filled(frame.width, frame.height + 2 * line, [255; 3]);
        img.pixels[..frame.pixels.len()].copy_from_slice(&frame.pixels);

        let s = &self.settings;
        let state = match (&self.failure, self.paused, self.rate) {
            (Some(why), _, _) => why.clone(),
            (None, true, _) => "paused".to_owned(),
            (None, false, Some(rate)) => format!("{rate:.0} steps/s"),
            (None, false, None) => "starting".to_owned(),
        };
        let cores = s.strategy.info().effective_cores(s.config.cores);
        let plural = if cores == 1 { "" } else { "s" };
        let status = format!(
            "{} ({cores} core{plural}, {} neighbours) · {state}",
            s.strategy, s.neighbors
        );
        let keys = "space pause · r reset · +/- N · s strategy · c colour · q quit";
        let x = f64::from(self.painter.layout().text_x);
        let first = f64::from(frame.height) + f64::from(line) * 0.8;
        text::draw(&mut img, &status, (x, first), em, [0; 3]);
        text::draw(&mut img, keys, (x, first + f64::from(line)), em, [96; 3]);
        img
    }
}

/// How a scene is drawn: its model, its view and the colour scales `c` switches between,
/// fixed by the initial state.
struct Looks {
    physics: Physics,
    view: View,
    speed: Scale,
    density: Scale,
}

impl Looks {
    /// The painter for `s`'s colour and width.
    fn painter(&self, s: &Settings) -> Painter {
        let scale = match s.color {
            ColorBy::Speed => self.speed,
            ColorBy::Density => self.density,
        };
        Painter::new(self.view, scale, s.width)
    }
}

/// A fresh dam break of `s` (through [`DamBreak::dam_break`], as the commands build it),
/// stepping on `s`'s strategy, and how to draw it.
fn build(s: &Settings) -> Result<(Stepper, Looks), TryReserveError> {
    let scene = DamBreak::dam_break(s.preset, s.n, s.seed)?;
    let looks = Looks {
        physics: scene.physics,
        view: View::of(&scene),
        speed: Scale::new(ColorBy::Speed, &scene.physics, &scene.state),
        density: Scale::new(ColorBy::Density, &scene.physics, &scene.state),
    };
    let sim = scene.simulate(s.neighbors);
    Ok((Stepper::new(sim, s.strategy, s.config, s.every), looks))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn settings() -> Settings {
        Settings {
            preset: Preset::Seed,
            n: 100,
            seed: 1,
            neighbors: NeighborMode::Grid,
            strategy: StrategyName::Seq,
            config: Config::new(2, 4),
            every: 3,
            color: ColorBy::Speed,
            width: 400,
        }
    }

    #[test]
    fn a_running_scene_advances_and_a_paused_one_does_not() {
        let mut scene = Scene::new(settings()).unwrap();
        scene.advance();
        assert_eq!(scene.steps_done(), 3);
        scene.apply(Action::TogglePause);
        scene.advance();
        assert_eq!(scene.steps_done(), 3);
        scene.apply(Action::TogglePause);
        scene.advance();
        assert_eq!(scene.steps_done(), 6);
    }

    #[test]
    fn reset_and_particle_keys_rebuild_the_scene_from_step_zero() {
        let mut scene = Scene::new(settings()).unwrap();
        scene.advance();
        scene.apply(Action::Reset);
        assert_eq!((scene.steps_done(), scene.settings().n), (0, 100));
        scene.apply(Action::MoreParticles);
        assert_eq!(scene.settings().n, 200);
        for _ in 0..10 {
            scene.apply(Action::FewerParticles);
        }
        assert_eq!(scene.settings().n, N_RANGE.0);
    }

    #[test]
    fn the_strategy_key_visits_every_strategy_and_comes_back() {
        let mut scene = Scene::new(settings()).unwrap();
        let mut seen = vec![scene.settings().strategy];
        for _ in 1..StrategyName::ALL.len() {
            scene.apply(Action::NextStrategy);
            scene.advance();
            seen.push(scene.settings().strategy);
        }
        assert_eq!(seen, StrategyName::ALL);
        scene.apply(Action::NextStrategy);
        assert_eq!(scene.settings().strategy, StrategyName::Seq);
        assert!(
            scene.steps_done() > 0,
            "switching strategy keeps the simulation"
        );
    }

    #[test]
    fn the_screen_is_the_frame_with_two_status_lines_below() {
        let scene = Scene::new(settings()).unwrap();
        let img = scene.draw();
        let frame = scene.painter.layout();
        assert_eq!(img.width, frame.width);
        assert!(img.height > frame.height);
        let inked = (frame.height..img.height)
            .flat_map(|y| (0..img.width).map(move |x| (x, y)))
            .filter(|&(x, y)| img.pixel(x, y)[0] < 128)
            .count();
        assert!(inked > 100, "{inked}");
    }

    #[test]
    fn a_wcsph_scene_runs_and_draws_its_time_and_walls() {
        let wcsph = Settings {
            preset: Preset::Wcsph,
            n: 128,
            ..settings()
        };
        let mut scene = Scene::new(wcsph).unwrap();
        scene.advance();
        assert_eq!(scene.steps_done(), 3);
        assert!(scene.sim.shown_time_s() > 0.0);
        let img = scene.draw();
        let grey = crate::render::frame::WALL_PARTICLE;
        assert!(
            img.pixels.chunks_exact(3).any(|p| p == grey),
            "wall particles"
        );
        scene.apply(Action::NextColor);
        scene.apply(Action::MoreParticles);
        assert_eq!((scene.steps_done(), scene.settings().n), (0, 256));
        scene.draw();
    }
}
