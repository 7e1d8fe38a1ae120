//! The constants of Müller's step, derived from the few that differ per preset (gravity, time
//! step, damping: [`Preset::params`](crate::models::Preset::params)); see the book's "Physics"
//! page, book/src/physics.md. Units: pixels (px), seconds (s), mass units (mu).

use glam::DVec2;
use std::f64::consts::PI;

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
    pub(crate) fn new(integrator: Integrator, gravity_y: f64, dt: f64, bound_damping: f64) -> Self {
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
