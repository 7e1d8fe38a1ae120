//! The constants of one step, per preset (see the book's "Physics" page,
//! book/src/physics.md). Units: pixels (px), seconds (s), mass units (mu).

use glam::DVec2;
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// Which source program's constants and integration order to reproduce.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Preset {
    /// The seed paper's Haskell program (`schuermannator/sph`), all f64.
    Seed,
    /// The C++ original (`cerrno/mueller-sph` at e0821c49), evaluated in f64.
    Cpp,
    /// Weakly compressible SPH in SI units, validated against Martin & Moyce (1952) (see
    /// [`crate::sph::wcsph`]).
    Wcsph,
}

impl Preset {
    /// Every preset, default first.
    pub const ALL: [Preset; 3] = [Preset::Seed, Preset::Cpp, Preset::Wcsph];

    /// The presets of Müller's pixel-unit model, whose constants are a [`Params`].
    pub const MUELLER: [Preset; 2] = [Preset::Seed, Preset::Cpp];

    /// The name used on the command line and in CSV files.
    pub fn as_str(self) -> &'static str {
        match self {
            Preset::Seed => "seed",
            Preset::Cpp => "cpp",
            Preset::Wcsph => "wcsph",
        }
    }

    /// Whether this is one of Müller's pixel-unit presets ([`Preset::MUELLER`]).
    pub fn is_mueller(self) -> bool {
        self != Preset::Wcsph
    }

    /// The constants of a Müller preset.
    ///
    /// # Panics
    /// For [`Preset::Wcsph`], whose constants depend on its resolution
    /// ([`crate::sph::wcsph::params::WcParams`]; [`crate::scene::Scene`] builds either).
    pub fn params(self) -> Params {
        match self {
            Preset::Seed => Params::new(Integrator::Seed, 12000.0 * -9.8, 0.0009, -1.0),
            Preset::Cpp => Params::new(Integrator::Cpp, -117600.0, 0.0008, -0.5),
            Preset::Wcsph => panic!("the wcsph preset has no Müller constants"),
        }
    }
}

impl std::fmt::Display for Preset {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

/// How velocity is updated from force (the two sources group the product differently).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Integrator {
    /// `v + DT * (f / rho)` (Haskell).
    Seed,
    /// `v + (DT * f) / rho` (C++).
    Cpp,
}

/// Every constant a step uses. Derived products are computed once here exactly as the
/// sources group them, so the passes only read them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Params {
    /// External acceleration-like force per density, px/s² (multiplied by rho, as in the sources).
    pub gravity: DVec2,
    /// Rest density REST_DENS.
    pub rest_density: f64,
    /// Gas constant GAS_CONST of the equation of state `p = k (rho - rho0)`.
    pub gas_const: f64,
    /// Kernel radius H, px.
    pub h: f64,
    /// H², px².
    pub hsq: f64,
    /// Particle mass MASS.
    pub mass: f64,
    /// Viscosity constant VISC.
    pub visc: f64,
    /// Time step DT, s.
    pub dt: f64,
    /// Poly6 kernel constant 315 / (65 π H⁹) (Müller 2003 eq. 20, with the sources' 65).
    pub poly6: f64,
    /// Spiky kernel gradient constant −45 / (π H⁶) (Müller 2003 eq. 21).
    pub spiky_grad: f64,
    /// Viscosity kernel Laplacian constant 45 / (π H⁶) (Müller 2003 eq. 22).
    pub visc_lap: f64,
    /// Wall margin EPS, px.
    pub eps: f64,
    /// Factor applied to a velocity component at a wall.
    pub bound_damping: f64,
    /// Velocity update grouping (and with it, the preset).
    pub integrator: Integrator,
    /// MASS · POLY6, as the sources' left-to-right `mass * poly6 * ...` computes it.
    pub mass_poly6: f64,
    /// VISC · MASS, as the sources' left-to-right `visc * mass * ...` computes it.
    pub visc_mass: f64,
}

impl Params {
    /// The preset these constants belong to.
    pub fn preset(&self) -> Preset {
        match self.integrator {
            Integrator::Seed => Preset::Seed,
            Integrator::Cpp => Preset::Cpp,
        }
    }

    fn new(integrator: Integrator, gravity_y: f64, dt: f64, bound_damping: f64) -> Self {
        let h: f64 = 16.0;
        let h6 = h * h * h * h * h * h;
        let h9 = h6 * h * h * h;
        let poly6 = 315.0 / (65.0 * PI * h9);
        let mass = 65.0;
        let visc = 250.0;
        Params {
            gravity: DVec2::new(0.0, gravity_y),
            rest_density: 1000.0,
            gas_const: 2000.0,
            h,
            hsq: h * h,
            mass,
            visc,
            dt,
            poly6,
            spiky_grad: -45.0 / (PI * h6),
            visc_lap: 45.0 / (PI * h6),
            eps: h,
            bound_damping,
            integrator,
            mass_poly6: mass * poly6,
            visc_mass: visc * mass,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    // The literals are the constants as printed in the design notes, to 17 digits.
    #[allow(clippy::excessive_precision)]
    #[test]
    fn seed_constants_have_the_bits_the_haskell_program_computes() {
        let p = Preset::Seed.params();
        assert_eq!(p.gravity.y.to_bits(), (-117600.00000000001455f64).to_bits());
        assert_ne!(
            p.gravity.y, -117600.0,
            "12000 * -9.8 is not exactly -117600 in f64"
        );
        assert_eq!(p.poly6, 2.2447474172780788e-11);
        assert_eq!(p.spiky_grad, -8.5377364625159387e-07);
        assert_eq!(p.visc_lap, 8.5377364625159387e-07);
        assert_eq!((p.dt, p.bound_damping, p.hsq), (0.0009, -1.0, 256.0));
    }

    #[test]
    fn cpp_constants_differ_only_in_gravity_time_step_and_damping() {
        let (s, c) = (Preset::Seed.params(), Preset::Cpp.params());
        assert_eq!(c.gravity, DVec2::new(0.0, -117600.0));
        assert_eq!((c.dt, c.bound_damping), (0.0008, -0.5));
        assert_eq!(c.integrator, Integrator::Cpp);
        let same = Params {
            gravity: s.gravity,
            dt: s.dt,
            bound_damping: s.bound_damping,
            integrator: s.integrator,
            ..c
        };
        assert_eq!(same, s);
    }
}
