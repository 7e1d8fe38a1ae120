//! What the viewer shows and how keys change it, without a window: a simulation, the painter
//! for its tank, and the settings the keys cycle through.

use sph_strategies::{Config, StrategyName};

use crate::render::frame::{Caption, Painter};
use crate::render::image::Image;
use crate::render::scale::{ColorBy, Scale};
use crate::render::text;
use crate::scene::dam_break;
use crate::solver::Simulation;
use crate::sph::neighbors::NeighborMode;
use crate::sph::params::Preset;
use crate::sph::state::State;
use crate::viewer::stepper::Stepper;

/// Fewest and most particles `+`/`-` reach.
pub const N_RANGE: (usize, usize) = (10, 1_000_000);

/// The viewer's settings: the keys change some of them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Settings {
    /// Constants and integration order.
    pub preset: Preset,
    /// Number of particles (`+` doubles, `-` halves).
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
    painter: Painter,
    paused: bool,
    /// Steps per second of the last advance, wall clock.
    rate: Option<f64>,
    /// Why the simulation stopped, if it did.
    failure: Option<String>,
}

impl Scene {
    /// The dam break of `settings`, at step 0, running.
    pub fn new(settings: Settings) -> Scene {
        let (sim, painter) = build(&settings);
        Scene {
            settings,
            sim,
            painter,
            paused: false,
            rate: None,
            failure: None,
        }
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
                self.painter = painter(s, &dam_break::initial_state(s.preset, s.n, s.seed));
                return;
            }
        }
        if action != Action::TogglePause {
            (self.sim, self.painter) = build(&self.settings);
            (self.rate, self.failure) = (None, None);
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
        let caption = Caption::at(step, state.len(), self.settings.preset);
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
        let x = f64::from(self.painter.layout().tank.x0);
        let first = f64::from(frame.height) + f64::from(line) * 0.8;
        text::draw(&mut img, &status, (x, first), em, [0; 3]);
        text::draw(&mut img, keys, (x, first + f64::from(line)), em, [96; 3]);
        img
    }
}

/// A fresh simulation, stepping on `s`'s strategy, and its painter.
fn build(s: &Settings) -> (Stepper, Painter) {
    let state = dam_break::initial_state(s.preset, s.n, s.seed);
    let painter = painter(s, &state);
    let domain = dam_break::domain(s.preset, s.n);
    let sim = Simulation::new(s.preset.params(), domain, state, s.neighbors);
    (Stepper::new(sim, s.strategy, s.config, s.every), painter)
}

/// The painter for `s`, whose colour scale is fixed by the `initial` state.
fn painter(s: &Settings, initial: &State) -> Painter {
    let params = s.preset.params();
    let scale = Scale::new(s.color, &params, initial);
    Painter::new(dam_break::domain(s.preset, s.n), params.h, scale, s.width)
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
            config: Config {
                cores: 2,
                chunks: 4,
            },
            every: 3,
            color: ColorBy::Speed,
            width: 400,
        }
    }

    #[test]
    fn a_running_scene_advances_and_a_paused_one_does_not() {
        let mut scene = Scene::new(settings());
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
        let mut scene = Scene::new(settings());
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
        let mut scene = Scene::new(settings());
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
        let scene = Scene::new(settings());
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
}
