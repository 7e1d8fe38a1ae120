//! The options that say which dam break a command simulates, shared (flattened) by `simulate`,
//! `render` and `trace`, and the one function that turns them into an initial state.

use std::path::PathBuf;

use anyhow::Context;
use clap::parser::ValueSource;
use clap::{ArgMatches, Args, FromArgMatches};

use crate::io::init_csv;
use crate::scene::{dam_break, memory};
use crate::sph::neighbors::NeighborMode;
use crate::sph::params::Preset;
use crate::sph::state::{Domain, State};

/// Which scene to simulate, and with which neighbour search.
#[derive(Debug, Clone)]
pub struct SceneArgs {
    /// Constants and integration order to reproduce.
    pub preset: Preset,
    /// Whether `--preset` was given on the command line (rather than defaulted).
    pub preset_given: bool,
    /// Number of particles (`None`: 1000, or the row count of `--init`).
    pub n: Option<usize>,
    /// Neighbour search.
    pub neighbors: NeighborMode,
    /// Seed of the initial jitter.
    pub seed: u64,
    /// Initial state from CSV.
    pub init: Option<PathBuf>,
}

/// The options as clap parses them; [`SceneArgs`] adds whether `--preset` was typed.
#[derive(Debug, Clone, Args)]
struct SceneOptions {
    /// Constants and integration order to reproduce.
    #[arg(long, default_value = "seed", value_parser = super::values::preset())]
    preset: Preset,
    /// Number of particles [default: 1000, or the row count of --init].
    #[arg(long, value_parser = super::particles)]
    n: Option<usize>,
    /// Neighbour search.
    #[arg(long, default_value = "all-pairs", value_parser = super::values::neighbors())]
    neighbors: NeighborMode,
    /// Seed of the initial jitter.
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
            neighbors: o.neighbors,
            seed: o.seed,
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
    /// The initial state and its tank, from `--init` or the preset's dam break of `--n`
    /// particles (default 1000) jittered with `--seed`. Refuses, before allocating the
    /// simulation, a run larger than the machine's memory ([`memory::check`]), and an init
    /// file dumped with another preset unless `--preset` was given.
    pub fn initial_state(&self) -> anyhow::Result<(State, Domain)> {
        let Some(path) = &self.init else {
            let n = self.n.unwrap_or(1000);
            memory::check(self.preset, self.neighbors, n, memory_available())?;
            let state = dam_break::try_initial_state(self.preset, n, self.seed)
                .with_context(|| format!("no memory for {n} particles"))?;
            return Ok((state, dam_break::domain(self.preset, n)));
        };
        let rows = init_csv::read(path)?;
        let count = rows.state.len();
        if let Some(asked) = self.n.filter(|&asked| asked != count) {
            anyhow::bail!(
                "--n {asked} conflicts with init file '{}', which holds {count} particles",
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
        let domain = dam_break::domain(self.preset, count);
        init_csv::check_walls(path, &rows, domain)?;
        Ok((rows.state, domain))
    }
}
