//! `bench-sph render`: the dam break as an animated GIF or PNG frames.
//!
//! Frame 0 is the initial state; then one frame every `--every` steps, so `--steps S
//! --every K` gives `floor(S / K) + 1` frames and runs `floor(S / K) · K` steps (steps past
//! the last frame would not be seen, so they are not run).

use std::io::IsTerminal;
use std::ops::ControlFlow;
use std::path::PathBuf;

use clap::Args;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

use super::simulate::say;
use crate::clock::Elapsed;
use crate::render::frame::{Caption, MAX_WIDTH, MIN_WIDTH, Painter};
use crate::render::output::Output;
use crate::render::scale::{ColorBy, Scale};
use crate::run::{Observer, Steps, run_steps};
use crate::solver::Simulation;
use crate::sph::params::Preset;

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
    /// One frame every K steps.
    #[arg(long, value_name = "K", default_value_t = 10, value_parser = super::positive)]
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
    /// left as they are; only frame files are replaced).
    #[arg(long, requires = "frames")]
    pub force: bool,
}

/// Runs `render`.
pub fn run(args: &RenderArgs) -> anyhow::Result<()> {
    let scene = args.scene.scene()?;
    let crate::sph::physics::Physics::Mueller(params) = scene.physics else {
        anyhow::bail!("render does not draw --preset wcsph yet");
    };
    let (state, domain) = (scene.state, scene.domain);
    let scale = Scale::new(args.color, &params, &state);
    let painter = Painter::new(domain, params.h, scale, args.width);
    let (width, height) = (painter.layout().width, painter.layout().height);

    // Open the output before simulating, so a bad path costs nothing.
    let mut output = open_output(args, &painter)?;

    let frames = args.steps / args.every + 1;
    let n = state.len();
    let config = args.parallel.config();
    let mut sim = Simulation::new(params, domain, state, args.scene.neighbors);
    let bar = progress_bar(frames, n * args.steps);
    let started = std::time::Instant::now();

    output.push(&painter.draw(&sim.state, &Caption::at(0, n, args.scene.preset)))?;
    bar.inc(1);
    let mut drawn = Frames {
        painter: &painter,
        preset: args.scene.preset,
        output: &mut output,
        bar: &bar,
        shown: 0,
        simulating_s: 0.0,
        failed: None,
    };
    let steps = Steps {
        total: (frames - 1) * args.every,
        every: args.every,
        warmup: 0,
        until_s: None,
    };
    // All frames in one session: one thread pool for the whole animation.
    let outcome = run_steps(
        &mut sim,
        args.parallel.strategy,
        &config,
        steps,
        &mut (),
        &mut drawn,
    );
    let (shown, simulating_s) = (drawn.shown, drawn.simulating_s);
    if let Some(err) = drawn.failed {
        return Err(err);
    }
    bar.finish_and_clear();
    let place = output.describe();
    output.finish()?;
    if let Err(err) = outcome {
        anyhow::bail!("{err} (the frames up to step {shown} are in {place})");
    }
    say(&format!(
        "{frames} frames of {width} × {height} px (steps 0 to {}, one every {}) written to {place}",
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
    preset: Preset,
    output: &'a mut Output,
    bar: &'a ProgressBar,
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
        let frame = self.painter.draw(
            &sim.state,
            &Caption::at(sim.steps_done, sim.state.len(), self.preset),
        );
        if let Err(err) = self.output.push(&frame) {
            self.failed = Some(err);
            return ControlFlow::Break(());
        }
        self.shown = sim.steps_done;
        self.bar.inc(1);
        ControlFlow::Continue(())
    }
}

/// A bar counting frames on stderr; hidden when stderr is not a terminal or the render is tiny.
fn progress_bar(frames: usize, particle_steps: usize) -> ProgressBar {
    if particle_steps < PROGRESS_FROM_PARTICLE_STEPS || !std::io::stderr().is_terminal() {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::with_draw_target(Some(frames as u64), ProgressDrawTarget::stderr());
    bar.set_style(
        ProgressStyle::with_template("{bar:40} {pos}/{len} frames, {elapsed} (eta {eta})")
            .expect("the template is valid"),
    );
    bar
}
