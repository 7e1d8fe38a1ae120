//! The options that say which dam break a command simulates, shared (flattened) by `simulate`,
//! `speedup`, `render` and `trace`, and the one function that turns them into an initial state.

use std::path::PathBuf;

use anyhow::Context;
use clap::parser::ValueSource;
use clap::{ArgMatches, Args, FromArgMatches};

use crate::io::init_csv;
use crate::models::Preset;
use crate::models::{mueller, wcsph};
use crate::scene::{Scene, memory};
use crate::solver::Simulation;
use crate::sph::neighbors::{NeighborMode, SumOrder};

/// Which scene to simulate, and with which neighbour search.
#[derive(Debug, Clone)]
pub struct SceneArgs {
    /// Constants and integration order to reproduce.
    pub preset: Preset,
    /// Whether `--preset` was given on the command line (rather than defaulted).
    pub preset_given: bool,
    /// Number of particles (`None`: 1000, or the row count of `--init`).
    pub n: Option<usize>,
    /// `wcsph` only: the resolution R = a/dx.
    pub resolution: Option<usize>,
    /// Neighbour search.
    pub neighbors: NeighborMode,
    /// Seed of the initial jitter.
    pub seed: u64,
    /// Whether `--seed` was given on the command line (rather than defaulted).
    pub seed_given: bool,
    /// Initial state from CSV.
    pub init: Option<PathBuf>,
}

/// The options as clap parses them; [`SceneArgs`] adds whether `--preset` was typed.
#[derive(Debug, Clone, Args)]
struct SceneOptions {
    /// Constants and integration order to reproduce.
    #[arg(long, default_value = "seed", value_parser = super::values::preset())]
    preset: Preset,
    /// Number of particles [default: 1000, or the row count of --init]. With --preset wcsph,
    /// the fluid particles: the resolution R with 2R² nearest N is used, and said.
    #[arg(long, value_parser = super::particles)]
    n: Option<usize>,
    /// --preset wcsph only: particles across the water column's width a (4..=400; 2R² fluid
    /// particles) [default: from --n, else 22].
    #[arg(long, value_name = "R", value_parser = super::resolution, conflicts_with_all = ["n", "init"])]
    resolution: Option<usize>,
    /// Neighbour search.
    #[arg(long, default_value = "all-pairs", value_parser = super::values::neighbors())]
    neighbors: NeighborMode,
    /// Seed of the initial jitter (--preset seed and cpp without --init; 0..=2^64-1).
    #[arg(long, default_value_t = 2019)]
    seed: u64,
    /// Initial state from CSV (header row; columns x,y required, vx,vy optional; a dump of
    /// another preset needs that --preset).
    #[arg(long, value_name = "FILE.csv")]
    init: Option<PathBuf>,
}

impl FromArgMatches for SceneArgs {
    fn from_arg_matches(matches: &ArgMatches) -> Result<Self, clap::Error> {
        let o = SceneOptions::from_arg_matches(matches)?;
        Ok(SceneArgs {
            preset: o.preset,
            preset_given: matches.value_source("preset") == Some(ValueSource::CommandLine),
            n: o.n,
            resolution: o.resolution,
            neighbors: o.neighbors,
            seed: o.seed,
            seed_given: matches.value_source("seed") == Some(ValueSource::CommandLine),
            init: o.init,
        })
    }

    fn update_from_arg_matches(&mut self, matches: &ArgMatches) -> Result<(), clap::Error> {
        *self = SceneArgs::from_arg_matches(matches)?;
        Ok(())
    }
}

impl Args for SceneArgs {
    fn group_id() -> Option<clap::Id> {
        SceneOptions::group_id()
    }

    fn augment_args(cmd: clap::Command) -> clap::Command {
        SceneOptions::augment_args(cmd)
    }

    fn augment_args_for_update(cmd: clap::Command) -> clap::Command {
        SceneOptions::augment_args_for_update(cmd)
    }
}

/// The memory available to a run (see [`memory::available_for_run`]).
pub(super) fn memory_available() -> Option<u64> {
    memory::available_for_run()
}

impl SceneArgs {
    /// The `wcsph` resolution these options ask for: `--resolution`, else the one nearest
    /// `--n` (default 1000); `None` for the other presets.
    pub fn wcsph_resolution(&self) -> Option<usize> {
        (self.preset == Preset::Wcsph).then(|| {
            self.resolution
                .unwrap_or_else(|| wcsph::scene::resolution_for(self.n.unwrap_or(1000)))
        })
    }

    /// The simulation of [`SceneArgs::scene`] with the neighbour search of `--neighbors`,
    /// summing in `order`, and its count of fluid particles (those that move); warns on
    /// standard error when `--n` gave way to a `wcsph` resolution.
    pub fn simulation(&self, order: SumOrder) -> anyhow::Result<(Simulation, usize)> {
        let scene = self.scene()?;
        if let Some(note) = self.resolution_note() {
            crate::output::console::warn(&note);
        }
        let fluid = scene.fluid();
        let sim = scene
            .simulate(self.neighbors)
            .with_sum_order(order)
            .context("--order cell needs --neighbors grid")?;
        Ok((sim, fluid))
    }

    /// A line saying which resolution `wcsph` runs at and why, when it is not the one given
    /// with `--resolution` (the commands print it on standard error).
    pub fn resolution_note(&self) -> Option<String> {
        let r = self.wcsph_resolution()?;
        let asked = self.n.filter(|_| self.resolution.is_none())?;
        let fluid = wcsph::scene::dam_break_particles(r);
        (asked != fluid).then(|| {
            format!(
                "note: --preset wcsph runs at resolution R = {r} ({fluid} fluid particles), \
                 the nearest to --n {asked}"
            )
        })
    }

    /// The initial state and its tank, from `--init` or the preset's dam break of `--n`
    /// particles (default 1000) jittered with `--seed` (for `wcsph`, at `--resolution`).
    /// Refuses, before allocating the simulation, a run larger than the machine's memory
    /// ([`memory::check`]), an init file dumped with another preset unless `--preset` was
    /// given, `--resolution` without `--preset wcsph`, and `--seed` where nothing is jittered.
    pub fn scene(&self) -> anyhow::Result<Scene> {
        if self.seed_given {
            if let Some(path) = &self.init {
                anyhow::bail!(
                    "--seed has nothing to seed with --init '{}': the file gives every \
                     particle's position; drop --seed",
                    path.display()
                );
            }
            if self.preset == Preset::Wcsph {
                anyhow::bail!(
                    "--seed has nothing to seed with --preset wcsph: its particles start on a \
                     lattice without jitter; drop --seed (the jittered presets are seed and cpp)"
                );
            }
        }
        if self.resolution.is_some() && self.preset != Preset::Wcsph {
            anyhow::bail!(
                "--resolution applies to --preset wcsph only; --preset {} takes --n",
                self.preset
            );
        }
        if let (Some(path), Preset::Wcsph) = (&self.init, self.preset) {
            anyhow::bail!(
                "--init '{}' cannot start --preset wcsph: its walls and hydrostatic densities \
                 come from --resolution",
                path.display()
            );
        }
        let Some(path) = &self.init else {
            let n = match self.wcsph_resolution() {
                Some(r) => wcsph::scene::dam_break_particles(r),
                None => self.n.unwrap_or(1000),
            };
            memory::check(self.preset, self.neighbors, n, memory_available())?;
            return Scene::dam_break(self.preset, n, self.seed)
                .with_context(|| format!("no memory for {n} particles"));
        };
        let rows = init_csv::read(path)?;
        let count = rows.state.len();
        if let Some(asked) = self.n.filter(|&asked| asked != count) {
            anyhow::bail!(
                "--n {asked} conflicts with init file '{}', which holds {count} particles",
                path.display()
            );
        }
        if rows.dumped.is_some_and(|d| d.preset == Preset::Wcsph) {
            anyhow::bail!(
                "init file '{}' was dumped with --preset wcsph, whose runs start from \
                 --resolution, not from a file",
                path.display()
            );
        }
        if let Some(dumped) = rows.dumped.filter(|d| d.preset != self.preset)
            && !self.preset_given
        {
            anyhow::bail!(
                "init file '{}' was dumped with --preset {}; pass --preset {} to continue it, \
                 or --preset {} explicitly to use {} physics",
                path.display(),
                dumped.preset,
                dumped.preset,
                self.preset,
                self.preset
            );
        }
        memory::check(self.preset, self.neighbors, count, memory_available())?;
        let domain = mueller::scene::domain(self.preset, count);
        init_csv::check_walls(path, &rows, domain)?;
        Ok(Scene {
            physics: self.preset.params().into(),
            domain,
            state: rows.state,
        })
    }
}
