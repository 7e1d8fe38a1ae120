//! `bench-sph render`: the dam break as an animated GIF or PNG frames.
//!
//! Frame 0 is the initial state; then one frame every `--every` steps, so `--steps S
//! --every K` gives `floor(S / K) + 1` frames and runs `floor(S / K) · K` steps (steps past
//! the last frame would not be seen, so they are not run). With `--t-end T` instead, frames
//! come every `--every` steps until the first step whose simulated time reaches T, which
//! gets the last frame: as many frames as that takes (`wcsph`'s time step adapts).
//!
//! Müller's presets are drawn in their pixel units, as the seed program showed them; `wcsph`
//! in metres, its wall particles included (see [`crate::render::frame`]).

use std::io::IsTerminal;
use std::ops::ControlFlow;
use std::path::PathBuf;

use clap::Args;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

use super::simulate::say;
use crate::clock::Elapsed;
use crate::limits;
use crate::models::Physics;
use crate::output::console;
use crate::render::frame::{Caption, MAX_WIDTH, MIN_WIDTH, Painter, View};
use crate::render::output::Output;
use crate::render::scale::{ColorBy, Scale};
use crate::run::{Observer, Steps, run_steps};
use crate::solver::Simulation;

/// Where the GIF goes when neither `--out` nor `--frames` is given.
const DEFAULT_OUT: &str = "dambreak.gif";

/// Renders below this many particle-steps finish too fast to need a progress bar.
const PROGRESS_FROM_PARTICLE_STEPS: usize = 1_000_000;

/// Options of `render`.
#[derive(Debug, Clone, Args)]
#[command(mut_args(super::parallel::strategy_help(
    "Parallel strategy (see `bench-sph list`); every strategy gives the same frames"
)))]
pub struct RenderArgs {
    /// The scene: preset, N, neighbour search, seed, initial state.
    #[command(flatten)]
    pub scene: super::scene::SceneArgs,
    /// Number of steps to show (frames at steps 0, K, 2K, … up to this).
    #[arg(long, default_value_t = 1000, value_parser = super::steps)]
    pub steps: usize,
    /// Show this much simulated time instead of a number of steps (s, 0 < T <= 100): frames
    /// every K steps, the last one after the first step that reaches T.
    #[arg(long, value_name = "SECONDS", value_parser = super::t_end, conflicts_with = "steps")]
    pub t_end: Option<f64>,
    /// One frame every K steps.
    #[arg(long, value_name = "K", default_value_t = 10, value_parser = super::steps)]
    pub every: usize,
    /// How the passes run: strategy, worker threads, chunks.
    #[command(flatten)]
    pub parallel: super::parallel::ParallelArgs,
    /// What the particles' colour shows (the range is fixed for the whole animation).
    #[arg(long, default_value = "speed", value_parser = super::values::color())]
    pub color: ColorBy,
    /// Image width, px (the height follows the tank's aspect ratio).
    #[arg(long, default_value_t = 600,
          value_parser = clap::value_parser!(u32).range(i64::from(MIN_WIDTH)..=i64::from(MAX_WIDTH)))]
    pub width: u32,
    /// GIF frames per second.
    #[arg(long, default_value_t = 20, value_parser = clap::value_parser!(u32).range(1..=50))]
    pub fps: u32,
    /// Write an animated GIF here [default: dambreak.gif].
    #[arg(long, value_name = "FILE.gif", conflicts_with = "frames")]
    pub out: Option<PathBuf>,
    /// Write PNG frames (frame_00000.png, …) into this folder instead of a GIF. Frames of an
    /// earlier render there are replaced (extra ones removed); other files make it refuse.
    #[arg(long, value_name = "DIR")]
    pub frames: Option<PathBuf>,
    /// With --frames: write into a folder that holds files render did not write (they are
    /// left as they are; only the frames the folder's record gives to render are replaced).
    #[arg(long, requires = "frames")]
    pub force: bool,
}

/// Runs `render`.
pub fn run(args: &RenderArgs) -> anyhow::Result<()> {
    let scene = args.scene.scene()?;
    if let Some(note) = args.scene.resolution_note() {
        console::warn(&note);
    }
    let scale = Scale::new(args.color, &scene.physics, &scene.state);
    let painter = Painter::new(View::of(&scene), scale, args.width);
    let (width, height) = (painter.layout().width, painter.layout().height);

    // Open the output before simulating, so a bad path costs nothing.
    let mut output = open_output(args, &painter)?;

    let steps = match args.t_end {
        None => Steps {
            total: args.steps / args.every * args.every,
            every: args.every,
            warmup: 0,
            until_s: None,
        },
        Some(t) => Steps {
            total: limits::MAX_STEPS,
            every: args.every,
            warmup: 0,
            until_s: Some(t),
        },
    };
    // Particles that move: what a step costs (wcsph's walls are fixed).
    let fluid = scene.fluid();
    let bar = progress_bar(args, &scene.physics, fluid);
    let config = args.parallel.config()?;
    let mut sim = scene.simulate(args.scene.neighbors);
    let started = std::time::Instant::now();

    output.push(&painter.draw(&sim.state, &Caption::of(&sim)))?;
    bar.inc(1);
    let mut drawn = Frames {
        painter: &painter,
        output: &mut output,
        bar: &bar,
        t_end: args.t_end,
        frames: 1,
        shown: 0,
        simulating_s: 0.0,
        failed: None,
    };
    // All frames in one session: one thread pool for the whole animation.
    let outcome = run_steps(&mut sim, args.parallel.strategy, &config, steps, &mut drawn);
    let (frames, shown, simulating_s) = (drawn.frames, drawn.shown, drawn.simulating_s);
    if let Some(err) = drawn.failed {
        return Err(err);
    }
    bar.finish_and_clear();
    let place = output.describe();
    output.finish()?;
    if let Err(err) = outcome {
        anyhow::bail!("{err} (the frames up to step {shown} are in {place})");
    }
    // Müller's captions count steps of a fixed dt; wcsph's time is worth saying.
    let time = match (sim.physics.fixed_dt(), args.t_end) {
        (Some(_), None) => String::new(),
        _ => format!(", simulated time 0 to {:.4} s", Caption::of(&sim).time_s),
    };
    say(&format!(
        "{frames} frames of {width} × {height} px (steps 0 to {}, one every {}{time}) written to {place}",
        sim.steps_done, args.every
    ))?;
    say(&format!(
        "{:.2} s in all, {simulating_s:.2} s of it simulating",
        started.elapsed().as_secs_f64()
    ))
}

/// The GIF file or PNG folder the frames go to.
fn open_output(args: &RenderArgs, painter: &Painter) -> anyhow::Result<Output> {
    match &args.frames {
        Some(dir) => Output::png_frames(dir, args.force),
        None => {
            let path = args.out.clone().unwrap_or_else(|| DEFAULT_OUT.into());
            let size = (painter.layout().width, painter.layout().height);
            Output::gif(&path, size, &painter.palette(), args.fps)
        }
    }
}

/// Draws a frame after every `--every` steps, outside the timed steps, and adds up the time
/// the steps took.
struct Frames<'a> {
    painter: &'a Painter,
    output: &'a mut Output,
    bar: &'a ProgressBar,
    /// `--t-end`: the bar then counts simulated time, ms, rather than frames.
    t_end: Option<f64>,
    /// Frames written so far.
    frames: usize,
    /// The step of the last frame written.
    shown: usize,
    /// Wall time of the steps so far, s.
    simulating_s: f64,
    /// Why a frame could not be written (the run then stops).
    failed: Option<anyhow::Error>,
}

impl Observer for Frames<'_> {
    fn segment(&mut self, sim: &Simulation, elapsed: Elapsed) -> ControlFlow<()> {
        self.simulating_s += elapsed.wall_s;
        let frame = self.painter.draw(&sim.state, &Caption::of(sim));
        if let Err(err) = self.output.push(&frame) {
            self.failed = Some(err);
            return ControlFlow::Break(());
        }
        self.frames += 1;
        self.shown = sim.steps_done;
        match self.t_end {
            None => self.bar.inc(1),
            Some(t) => self.bar.set_position(milliseconds(sim.time_s.min(t))),
        }
        ControlFlow::Continue(())
    }
}

/// A bar on stderr counting frames, or with `--t-end` simulated milliseconds; hidden when
/// stderr is not a terminal or the render is tiny (estimated from the first time step for
/// `--t-end`: wcsph's shrinks by at most a tenth as the flow speeds up).
fn progress_bar(args: &RenderArgs, physics: &Physics, fluid: usize) -> ProgressBar {
    let steps = match args.t_end {
        None => args.steps,
        Some(t) => (t / physics.first_dt()) as usize,
    };
    if fluid.saturating_mul(steps) < PROGRESS_FROM_PARTICLE_STEPS
        || !std::io::stderr().is_terminal()
    {
        return ProgressBar::hidden();
    }
    let (len, template) = match args.t_end {
        None => (
            (args.steps / args.every + 1) as u64,
            "{bar:40} {pos}/{len} frames, {elapsed} (eta {eta})",
        ),
        Some(t) => (
            milliseconds(t),
            "{bar:40} {pos}/{len} ms simulated, {elapsed} (eta {eta})",
        ),
    };
    let bar = ProgressBar::with_draw_target(Some(len), ProgressDrawTarget::stderr());
    bar.set_style(ProgressStyle::with_template(template).expect("the template is valid"));
    bar
}

/// `seconds` in whole milliseconds, for the progress bar.
fn milliseconds(seconds: f64) -> u64 {
    (seconds * 1000.0).round() as u64
}
