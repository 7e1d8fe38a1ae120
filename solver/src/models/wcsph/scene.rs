//! The `wcsph` preset's scenes, in SI units: a tank 5a long with walls 2.5a high
//! (a = [`COLUMN_WIDTH`]), its inner faces at x = 0, x = 5a and y = 0, open at the top.
//!
//! - **Dam break** (Martin & Moyce 1952's square column, n² = 2): fluid a wide and 2a high
//!   against the left wall, particles at ((i + ½) dx, (j + ½) dx), i < R, j < 2R, row by row
//!   from the bottom.
//! - **Still water** (a test that the walls hold a tank at rest): fluid across the whole
//!   tank to depth a.
//!
//! The walls are ⌈2h/dx⌉ layers of fixed particles on the same lattice, outside the inner
//! faces: left and right walls as high as the tank, the floor under both (corners included).
//! They follow the fluid in the state. The fluid starts at rest and hydrostatic:
//! ρ = ρ0 (1 + ρ0 g (H − y) / B)^(1/7) for a free surface at height H; no jitter (the seed
//! is unused).

use std::collections::TryReserveError;

use crate::models::wcsph::params::{COLUMN_WIDTH, WcParams};
use crate::sph::state::{Domain, State, try_zeros};

/// The tank's length, in column widths (the experiment's data runs to Z = 4.11).
pub const TANK_LENGTH: f64 = 5.0;
/// The walls' height, in column widths.
pub const WALL_HEIGHT: f64 = 2.5;

/// Which fluid the tank holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Fill {
    /// The dam-break column, a × 2a against the left wall.
    DamBreak,
    /// Still water across the tank, depth a.
    StillWater,
}

impl Fill {
    /// Fluid particles (columns, rows) at resolution R.
    fn lattice(self, resolution: usize) -> (usize, usize) {
        match self {
            Fill::DamBreak => (resolution, 2 * resolution),
            Fill::StillWater => (TANK_LENGTH as usize * resolution, resolution),
        }
    }
}

/// The tank's inner faces: x from 0 to 5a, y from 0 to 2.5a, m.
pub fn domain() -> Domain {
    Domain {
        width: TANK_LENGTH * COLUMN_WIDTH,
        height: WALL_HEIGHT * COLUMN_WIDTH,
    }
}

/// Fluid particles of the dam break at resolution R: 2R².
pub fn dam_break_particles(resolution: usize) -> usize {
    let (cols, rows) = Fill::DamBreak.lattice(resolution);
    cols * rows
}

/// The resolution whose dam break has the fluid-particle count nearest `n` (2R² ≈ n; ties
/// go to the smaller R), within [`crate::models::wcsph::params::RESOLUTIONS`].
pub fn resolution_for(n: usize) -> usize {
    let range = crate::models::wcsph::params::RESOLUTIONS;
    let below = ((n as f64 / 2.0).sqrt().floor() as usize).clamp(*range.start(), *range.end());
    let above = (below + 1).min(*range.end());
    let gap = |r: usize| dam_break_particles(r).abs_diff(n);
    if gap(above) < gap(below) {
        above
    } else {
        below
    }
}

/// Wall particles at resolution R.
pub fn wall_particles(resolution: usize) -> usize {
    wall_positions(&WcParams::new(resolution, 0)).len()
}

/// The scene `fill` at resolution R: its constants and its state (fluid, then walls).
pub fn build(fill: Fill, resolution: usize) -> Result<(WcParams, State), TryReserveError> {
    let (cols, rows) = fill.lattice(resolution);
    let fluid = cols * rows;
    let prm = WcParams::new(resolution, fluid);
    let walls = wall_positions(&prm);
    let n = fluid + walls.len();
    let (mut x, mut y) = (Vec::new(), Vec::new());
    x.try_reserve_exact(n)?;
    y.try_reserve_exact(n)?;
    for j in 0..rows {
        for i in 0..cols {
            x.push((i as f64 + 0.5) * prm.dx);
            y.push((j as f64 + 0.5) * prm.dx);
        }
    }
    for &(wx, wy) in &walls {
        x.push(wx);
        y.push(wy);
    }
    let surface = rows as f64 * prm.dx;
    let mut state = State::try_from_kinematics(x, y, try_zeros(n)?, try_zeros(n)?)?;
    for k in 0..n {
        let depth = if k < fluid { surface - state.y[k] } else { 0.0 };
        let rho = hydrostatic_density(&prm, depth);
        (state.rho[k], state.p[k]) = (rho, prm.pressure(rho));
    }
    Ok((prm, state))
}

/// The density at `depth` below a free surface at rest: ρ0 (1 + ρ0 g depth / B)^(1/7).
fn hydrostatic_density(prm: &WcParams, depth: f64) -> f64 {
    let g = -prm.gravity.y;
    prm.rho0 * (1.0 + prm.rho0 * g * depth / prm.tait_b).powf(1.0 / 7.0)
}

/// The walls' particles, layer by layer outwards: the floor (corners included), then the
/// left and the right wall above it.
fn wall_positions(prm: &WcParams) -> Vec<(f64, f64)> {
    let layers = prm.wall_layers();
    let d = domain();
    let along = (d.width / prm.dx).round() as usize;
    let up = (d.height / prm.dx).ceil() as usize;
    let mut out = Vec::with_capacity(layers * (along + 2 * layers + 2 * up));
    for k in 0..layers {
        let y = -(k as f64 + 0.5) * prm.dx;
        for i in 0..along + 2 * layers {
            out.push(((i as f64 - layers as f64 + 0.5) * prm.dx, y));
        }
    }
    for k in 0..layers {
        for j in 0..up {
            let y = (j as f64 + 0.5) * prm.dx;
            out.push((-(k as f64 + 0.5) * prm.dx, y));
            out.push((d.width + (k as f64 + 0.5) * prm.dx, y));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_dam_is_a_by_2a_against_the_left_wall_on_the_floor() {
        let (prm, s) = build(Fill::DamBreak, 20).unwrap();
        assert_eq!(prm.fluid, 800);
        let fluid = |v: &[f64]| v[..prm.fluid].iter().cloned().fold(f64::NAN, f64::max);
        let min = |v: &[f64]| v[..prm.fluid].iter().cloned().fold(f64::NAN, f64::min);
        assert!((min(&s.x) - 0.025).abs() < 1e-12 && (fluid(&s.x) - 0.975).abs() < 1e-12);
        assert!((min(&s.y) - 0.025).abs() < 1e-12 && (fluid(&s.y) - 1.975).abs() < 1e-12);
    }

    #[test]
    fn walls_surround_the_tank_outside_its_inner_faces() {
        let (prm, s) = build(Fill::DamBreak, 20).unwrap();
        let d = domain();
        assert_eq!(s.len() - prm.fluid, wall_particles(20));
        for k in prm.fluid..s.len() {
            let (x, y) = (s.x[k], s.y[k]);
            let outside = x < 0.0 || x > d.width || y < 0.0;
            assert!(
                outside,
                "wall particle {k} at ({x}, {y}) is inside the tank"
            );
            assert!(x > -prm.support - prm.dx && x < d.width + prm.support + prm.dx);
            assert!(y > -prm.support - prm.dx && y < d.height);
        }
        assert!(s.vx.iter().chain(&s.vy).all(|&v| v == 0.0));
    }

    #[test]
    fn the_fluid_starts_hydrostatic() {
        let (prm, s) = build(Fill::StillWater, 10).unwrap();
        for k in 0..prm.fluid {
            let depth = 1.0 - s.y[k];
            let expected = prm.rho0 * 9.81 * depth;
            assert!(
                (s.p[k] - expected).abs() < 1e-3 * expected,
                "{k}: {}",
                s.p[k]
            );
        }
    }

    #[test]
    fn n_maps_to_the_nearest_resolution() {
        assert_eq!(resolution_for(3200), 40);
        assert_eq!(resolution_for(1000), 22); // 968 is nearer than 1058
        assert_eq!(resolution_for(1), 4);
        assert_eq!(resolution_for(usize::MAX), 400);
        assert_eq!(dam_break_particles(40), 3200);
    }
}
