//! Which model a simulation steps: Müller's pixel-unit fluid or weakly compressible SPH.

use super::neighbors::Bounds;
use super::params::{Params, Preset};
use super::state::Domain;
use super::wcsph::params::WcParams;

/// The constants of a run, and with them the model and its passes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Physics {
    /// Müller et al. 2003 as the seed and C++ sources compute it (`seed`, `cpp`).
    Mueller(Params),
    /// Weakly compressible SPH in SI units (`wcsph`).
    Wcsph(WcParams),
}

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
        match self {
            Physics::Mueller(p) => p.preset(),
            Physics::Wcsph(_) => Preset::Wcsph,
        }
    }

    /// The neighbour search radius: H (px) for Müller, the kernel support 2h (m) for WCSPH.
    pub fn search_radius(&self) -> f64 {
        match self {
            Physics::Mueller(p) => p.h,
            Physics::Wcsph(p) => p.support,
        }
    }

    /// Particles that move (the rest are fixed walls): all of `n` for Müller.
    pub fn fluid(&self, n: usize) -> usize {
        match self {
            Physics::Mueller(_) => n,
            Physics::Wcsph(p) => p.fluid.min(n),
        }
    }

    /// The rectangle the grid covers: the domain, and for WCSPH the walls' particle layers
    /// outside it (left, right and below).
    pub fn search_bounds(&self, domain: Domain) -> Bounds {
        let walls = match self {
            Physics::Mueller(_) => 0.0,
            Physics::Wcsph(p) => p.wall_layers() as f64 * p.dx,
        };
        let inner = Bounds::of(domain);
        Bounds {
            min_x: inner.min_x - walls,
            min_y: inner.min_y - walls,
            max_x: inner.max_x + walls,
            max_y: inner.max_y,
        }
    }
}
