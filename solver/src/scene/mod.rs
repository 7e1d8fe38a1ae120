//! Initial states: [`Scene`] is the one way a command turns a preset and a size into a
//! simulation (each model's layout is its folder's `scene`), and [`memory`] what its run needs.

pub mod memory;
pub mod splitmix;

use std::collections::TryReserveError;

use crate::models::{Physics, Preset, mueller, wcsph};
use crate::solver::Simulation;
use crate::sph::neighbors::NeighborMode;
use crate::sph::state::{Domain, State};

/// A preset's initial state, ready to simulate.
#[derive(Debug, Clone)]
pub struct Scene {
    /// The model and its constants.
    pub physics: Physics,
    /// The tank.
    pub domain: Domain,
    /// The particles (for `wcsph`, the fluid then the walls).
    pub state: State,
}

impl Scene {
    /// The dam break of `preset` for `n` particles: Müller's presets place `n` jittered by
    /// `seed`; `wcsph` takes the resolution whose fluid count is nearest `n`
    /// ([`wcsph::scene::resolution_for`]) and has no jitter.
    pub fn dam_break(preset: Preset, n: usize, seed: u64) -> Result<Scene, TryReserveError> {
        match preset {
            Preset::Wcsph => Scene::tank(
                wcsph::scene::Fill::DamBreak,
                wcsph::scene::resolution_for(n),
            ),
            Preset::Seed | Preset::Cpp => Ok(Scene {
                physics: preset.params().into(),
                domain: mueller::scene::domain(preset, n),
                state: mueller::scene::try_initial_state(preset, n, seed)?,
            }),
        }
    }

    /// The fluid particles of [`Scene::dam_break`]`(preset, n, _)` (without building it): `n`,
    /// or for `wcsph` those of the resolution nearest `n`. A sweep's group is named by it.
    pub fn dam_break_fluid(preset: Preset, n: usize) -> usize {
        match preset {
            Preset::Wcsph => wcsph::scene::dam_break_particles(wcsph::scene::resolution_for(n)),
            Preset::Seed | Preset::Cpp => n,
        }
    }

    /// The `wcsph` tank holding `fill` at resolution R.
    pub fn tank(fill: wcsph::scene::Fill, resolution: usize) -> Result<Scene, TryReserveError> {
        let (prm, state) = wcsph::scene::build(fill, resolution)?;
        Ok(Scene {
            physics: prm.into(),
            domain: wcsph::scene::domain(),
            state,
        })
    }

    /// Particles that move (the rest are walls).
    pub fn fluid(&self) -> usize {
        self.physics.fluid(self.state.len())
    }

    /// The simulation of this scene with neighbour search `mode`.
    pub fn simulate(self, mode: NeighborMode) -> Simulation {
        Simulation::new(self.physics, self.domain, self.state, mode)
    }
}
