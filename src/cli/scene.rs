//! The options that say which dam break a command simulates, shared (flattened) by `simulate`,
//! `render` and `trace`, and the one function that turns them into an initial state.

use std::path::PathBuf;

use clap::Args;

use crate::io::init_csv;
use crate::scene::dam_break;
use crate::sph::neighbors::NeighborMode;
use crate::sph::params::Preset;
use crate::sph::state::{Domain, State};

/// Which scene to simulate, and with which neighbour search.
#[derive(Debug, Clone, Args)]
pub struct SceneArgs {
    /// Constants and integration order to reproduce.
    #[arg(long, value_enum, default_value_t = Preset::Seed)]
    pub preset: Preset,
    /// Number of particles [default: 1000, or the row count of --init].
    #[arg(long, value_parser = super::particles)]
    pub n: Option<usize>,
    /// Neighbour search.
    #[arg(long, value_enum, default_value_t = NeighborMode::AllPairs)]
    pub neighbors: NeighborMode,
    /// Seed of the initial jitter.
    #[arg(long, default_value_t = 2019)]
    pub seed: u64,
    /// Initial state from CSV (header row; columns x,y required, vx,vy optional).
    #[arg(long, value_name = "FILE.csv")]
    pub init: Option<PathBuf>,
}

impl SceneArgs {
    /// The initial state and its tank, from `--init` or the preset's dam break of `--n`
    /// particles (default 1000) jittered with `--seed`.
    pub fn initial_state(&self) -> anyhow::Result<(State, Domain)> {
        let Some(path) = &self.init else {
            let n = self.n.unwrap_or(1000);
            return Ok((
                dam_break::initial_state(self.preset, n, self.seed),
                dam_break::domain(self.preset, n),
            ));
        };
        let rows = init_csv::read(path)?;
        let count = rows.state.len();
        if let Some(asked) = self.n.filter(|&asked| asked != count) {
            anyhow::bail!(
                "--n {asked} conflicts with init file '{}', which holds {count} particles",
                path.display()
            );
        }
        let domain = dam_break::domain(self.preset, count);
        init_csv::check_walls(path, &rows, domain)?;
        Ok((rows.state, domain))
    }
}
