//! Weakly compressible SPH in SI units: the `wcsph` preset, a dam break that a fluid-dynamics
//! reader accepts and that `bench-sph validate` checks against Martin & Moyce (1952).
//!
//! Wendland C2 kernel (h = 1.3 dx, support 2h), Tait's equation of state (γ = 7,
//! c0 = 10 √(2g·2a)), continuity with Molteni–Colagrossi density diffusion (δ = 0.1),
//! momentum with Monaghan's artificial viscosity (α = 0.02), walls of fixed dummy particles
//! whose pressure is extrapolated from the fluid (Adami, Hu & Adams 2012). Sources: PySPH
//! `examples/dam_break_2d.py`, TrixiParticles `examples/fluid/dam_break_2d.jl`,
//! DualSPHysics `CaseDambreakVal2D`.
//!
//! A step: the largest fluid speed sets dt (a parallel reduction); the walls' pressure from
//! the fluid; the acceleration of every fluid particle at (xⁿ, vⁿ, ρⁿ); the density rate
//! with the kicked velocities vⁿ⁺¹ = vⁿ + dt·a; then each particle kicks, updates ρ and p,
//! and drifts with vⁿ⁺¹. (Updating ρ with the old velocity makes a still tank blow up.)

pub mod by_eight;
pub mod kept;
pub mod model;
pub mod pairs;
pub mod params;
pub mod passes;
pub mod scene;
