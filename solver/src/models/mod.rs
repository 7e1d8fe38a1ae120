//! The models, one folder each, and their registry. A model's folder holds its constants
//! (`params`), its per-particle passes (`passes`, pure), the solver's view of it (`model`: a
//! [`Model`]) and its initial state (`scene`): [`mueller`] (the `seed` and `cpp` presets) and
//! [`wcsph`]. This file is the registry: a variant of [`Physics`], its `From` and its arm of
//! `with_model!` per model, and the user's names for them ([`Preset`]). Everything a model is
//! (its preset, search, passes and schedule) it says through [`Model`]; this file only names
//! them.

pub mod mueller;
mod preset;
pub mod wcsph;

pub use preset::Preset;

use crate::solver::model::{Model, Units};
use crate::solver::pass::Pass;
use crate::sph::neighbors::Bounds;
use crate::sph::state::{Domain, State};
use mueller::params::Params;
use wcsph::params::WcParams;

/// The constants of a run, and with them the model and its passes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Physics {
    /// Müller et al. 2003 as the seed and C++ sources compute it (`seed`, `cpp`).
    Mueller(Params),
    /// Weakly compressible SPH in SI units (`wcsph`).
    Wcsph(WcParams),
}

/// Runs `$body` with `$m` bound to the model's constants inside `$physics` (a `Physics`, or
/// a reference to one): a type that implements [`Model`], so that `$body` is compiled per
/// model.
macro_rules! with_model {
    ($physics:expr, $m:ident => $body:expr) => {
        match $physics {
            $crate::models::Physics::Mueller($m) => $body,
            $crate::models::Physics::Wcsph($m) => $body,
        }
    };
}
pub(crate) use with_model;

impl From<Params> for Physics {
    fn from(p: Params) -> Self {
        Physics::Mueller(p)
    }
}

impl From<WcParams> for Physics {
    fn from(p: WcParams) -> Self {
        Physics::Wcsph(p)
    }
}

impl Physics {
    /// The preset these constants belong to.
    pub fn preset(&self) -> Preset {
        with_model!(self, m => m.preset())
    }

    /// The neighbour search radius: H (px) for Müller, the kernel support 2h (m) for WCSPH.
    pub fn search_radius(&self) -> f64 {
        with_model!(self, m => m.search_radius())
    }

    /// Particles that move (the rest are fixed walls): all of `n` for Müller.
    pub fn fluid(&self, n: usize) -> usize {
        with_model!(self, m => m.fluid(n))
    }

    /// The time step when the model fixes it (Müller's `dt`); `None` where it adapts (WCSPH).
    pub fn fixed_dt(&self) -> Option<f64> {
        with_model!(self, m => m.fixed_dt())
    }

    /// The first step's time step, from fluid at rest (see [`Model::first_dt`]).
    pub fn first_dt(&self) -> f64 {
        with_model!(self, m => m.first_dt())
    }

    /// How far outside the domain the walls' particles lie (0: the walls are the domain's
    /// edges, as in Müller's model).
    pub fn wall_depth(&self) -> f64 {
        with_model!(self, m => m.wall_depth())
    }

    /// The units the model computes in.
    pub fn units(&self) -> Units {
        with_model!(self, m => m.units())
    }

    /// The radius a picture draws a particle with (see [`Model::drawn_radius`]).
    pub fn drawn_radius(&self) -> f64 {
        with_model!(self, m => m.drawn_radius())
    }

    /// The speeds a picture of a run from `initial` colours against.
    pub fn speed_range(&self, initial: &State) -> (f64, f64) {
        with_model!(self, m => m.speed_range(initial))
    }

    /// The densities a picture colours against.
    pub fn density_range(&self) -> (f64, f64) {
        with_model!(self, m => m.density_range())
    }

    /// The model's passes, in step order.
    pub fn passes(&self) -> &'static [Pass] {
        with_model!(self, m => m.passes())
    }

    /// The rectangle the grid covers: the domain, and for WCSPH the walls' particle layers
    /// outside it (left, right and below).
    pub fn search_bounds(&self, domain: Domain) -> Bounds {
        let walls = self.wall_depth();
        let inner = Bounds::of(domain);
        Bounds {
            min_x: inner.min_x - walls,
            min_y: inner.min_y - walls,
            max_x: inner.max_x + walls,
            max_y: inner.max_y,
        }
    }
}
