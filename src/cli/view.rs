//! `bench-sph view` (cargo feature `viewer`): the dam break live in a window.

use clap::Args;

use crate::models::Preset;
use crate::render::frame::{MAX_WIDTH, MIN_WIDTH};
use crate::render::scale::ColorBy;
use crate::scene::memory;
use crate::sph::neighbors::NeighborMode;
use crate::viewer::scene::Settings;

/// Options of `view`.
#[derive(Debug, Clone, Args)]
#[command(mut_args(super::parallel::strategy_help(
    "Parallel strategy at start (s moves to the next)"
)))]
pub struct ViewArgs {
    /// Constants and integration order to reproduce.
    #[arg(long, default_value = "seed", value_parser = super::values::preset())]
    pub preset: Preset,
    /// Number of particles at start (+ and - double and halve it).
    #[arg(long, default_value_t = 1000, value_parser = super::particles)]
    pub n: usize,
    /// Steps between two frames on screen.
    #[arg(long, value_name = "K", default_value_t = 5, value_parser = super::steps)]
    pub every: usize,
    /// Neighbour search.
    #[arg(long, default_value = "grid", value_parser = super::values::neighbors())]
    pub neighbors: NeighborMode,
    /// How the passes run: strategy, worker threads, chunks.
    #[command(flatten)]
    pub parallel: super::parallel::ParallelArgs,
    /// Seed of the initial jitter.
    #[arg(long, default_value_t = 2019)]
    pub seed: u64,
    /// What the particles' colour shows at start (c switches).
    #[arg(long, default_value = "speed", value_parser = super::values::color())]
    pub color: ColorBy,
    /// Window width, px.
    #[arg(long, default_value_t = 800,
          value_parser = clap::value_parser!(u32).range(i64::from(MIN_WIDTH)..=i64::from(MAX_WIDTH)))]
    pub width: u32,
}

/// Runs `view`.
pub fn run(args: &ViewArgs) -> anyhow::Result<()> {
    // Checked before the window opens; + doubles N only up to the viewer's own bound.
    memory::check(
        args.preset,
        args.neighbors,
        args.n,
        super::scene::memory_available(),
    )?;
    crate::viewer::run(Settings {
        preset: args.preset,
        n: args.n,
        seed: args.seed,
        neighbors: args.neighbors,
        strategy: args.parallel.strategy,
        config: args.parallel.config()?,
        every: args.every,
        color: args.color,
        width: args.width,
    })
}
