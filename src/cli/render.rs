//! `bench-sph render`: the dam break as an animated GIF or PNG frames.
//!
//! Frame 0 is the initial state; then one frame every `--every` steps, so `--steps S
//! --every K` gives `floor(S / K) + 1` frames and runs `floor(S / K) · K` steps (steps past
//! the last frame would not be seen, so they are not run).

use std::io::IsTerminal;
use std::path::PathBuf;

use clap::Args;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

use super::simulate::say;
use crate::render::frame::{Caption, MAX_WIDTH, MIN_WIDTH, Painter};
use crate::render::output::Output;
use crate::render::scale::{ColorBy, Scale};
use crate::run::run_timed;
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
    let (state, domain) = args.scene.initial_state()?;
    let params = args.scene.preset.params();
    let scale = Scale::new(args.color, &params, &state);
    let painter = Painter::new(domain, params.h, scale, args.width);
    let (width, height) = (painter.layout().width, painter.layout().height);

    // Open the output before simulating, so a bad path costs nothing.
    let mut output = match &args.frames {
        Some(dir) => Output::png_frames(dir, args.force)?,
        None => {
            let path = args.out.clone().unwrap_or_else(|| DEFAULT_OUT.into());
            Output::gif(&path, (width, height), &painter.palette(), args.fps)?
        }
    };

    let frames = args.steps / args.every + 1;
    let n = state.len();
    let config = args.parallel.config();
    let mut sim = Simulation::new(params, domain, state, args.scene.neighbors);
    let caption = |sim: &Simulation| Caption {
        step: sim.steps_done,
        time_s: sim.steps_done as f64 * sim.params.dt,
        n,
        preset: args.scene.preset,
    };
    let bar = progress_bar(frames, n * args.steps);
    let started = std::time::Instant::now();
    let mut simulating_s = 0.0;

    output.push(&painter.draw(&sim.state, &caption(&sim)))?;
    bar.inc(1);
    for _ in 1..frames {
        let shown = sim.steps_done;
        match run_timed(&mut sim, args.parallel.strategy, &config, args.every) {
            Ok(elapsed) => simulating_s += elapsed.wall_s,
            Err(err) => {
                bar.finish_and_clear();
                let place = output.describe();
                output.finish()?;
                anyhow::bail!("{err} (the frames up to step {shown} are in {place})");
            }
        }
        output.push(&painter.draw(&sim.state, &caption(&sim)))?;
        bar.inc(1);
    }
    bar.finish_and_clear();
    let place = output.describe();
    output.finish()?;
    say(&format!(
        "{frames} frames of {width} × {height} px (steps 0 to {}, one every {}) written to {place}",
        sim.steps_done, args.every
    ))?;
    say(&format!(
        "{:.2} s in all, {simulating_s:.2} s of it simulating",
        started.elapsed().as_secs_f64()
    ))
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
