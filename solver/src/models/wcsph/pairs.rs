//! The momentum and continuity pair terms of eight pairs at once, lane by lane, as the same
//! scalar operations in the same order (no fused multiply-add, no reassociation): each lane
//! has the bits one pair computed alone has. A lane is one pair (a, b); the eight may share
//! their particle a (one particle's neighbours, eight at a time:
//! [`super::passes::acceleration`]) or not (eight particles, each its m-th neighbour:
//! [`super::by_eight`]).
//!
//! A lane whose `keep` is false, or whose neighbour lies at 2h or beyond (a list holds
//! neighbours out to 2h + skin), gives +0: the caller adds it all the same, and a sum that
//! starts at +0 is unchanged by adding ±0, so the sums have the bits of the pairs within 2h
//! added one by one.
//!
//! The arrays of eight are written as plain loops, and the neighbours' fields gathered into
//! arrays first, so that the compiler runs the arithmetic in whole registers of the run's
//! SIMD path (inside [`crate::simd::Lanes::vectorize`]); `array::map` and `array::from_fn`
//! were left as calls there.

use glam::DVec2;

use super::params::WcParams;
use crate::sph::state::{Fields, Positions};

/// Eight lanes.
pub type F8 = [f64; 8];

/// Read-only inputs of the continuity pass: the fields at the start of the step and every
/// particle's velocity after this step's kick ([`super::passes::kick`], written by the momentum pass; zero for
/// the walls, which stay at rest).
#[derive(Debug, Clone, Copy)]
pub struct ContinuityInputs<'a> {
    /// The fields at the start of the step.
    pub fields: Fields<'a>,
    /// Kicked velocity x of every particle, m/s.
    pub kicked_x: &'a [f64],
    /// Kicked velocity y.
    pub kicked_y: &'a [f64],
}

/// What the momentum term needs of particle a, in each lane.
#[derive(Debug, Clone, Copy)]
pub struct MomentumSide {
    /// x_a, m.
    pub x: F8,
    /// y_a, m.
    pub y: F8,
    /// v_a, x, m/s.
    pub vx: F8,
    /// v_a, y, m/s.
    pub vy: F8,
    /// ρ_a, kg/m³.
    pub rho: F8,
    /// p_a/ρ_a², m⁵/(kg s²).
    pub own: F8,
}

impl MomentumSide {
    /// Particle `a` in every lane.
    #[inline(always)]
    pub fn splat(a: usize, f: &Fields<'_>) -> MomentumSide {
        let (rho, p) = (f.rho[a], f.p[a]);
        MomentumSide {
            x: [f.pos.x[a]; 8],
            y: [f.pos.y[a]; 8],
            vx: [f.vx[a]; 8],
            vy: [f.vy[a]; 8],
            rho: [rho; 8],
            own: [p / (rho * rho); 8],
        }
    }

    /// Particles `a0..a0 + 8`, one a lane.
    #[inline(always)]
    pub fn eight(a0: usize, f: &Fields<'_>) -> MomentumSide {
        let (rho, p) = (run(a0, f.rho), run(a0, f.p));
        let mut own = [0.0; 8];
        for k in 0..8 {
            own[k] = p[k] / (rho[k] * rho[k]);
        }
        MomentumSide {
            x: run(a0, f.pos.x),
            y: run(a0, f.pos.y),
            vx: run(a0, f.vx),
            vy: run(a0, f.vy),
            rho,
            own,
        }
    }
}

/// What the continuity term needs of particle a, in each lane.
#[derive(Debug, Clone, Copy)]
pub struct ContinuitySide {
    /// x_a, m.
    pub x: F8,
    /// y_a, m.
    pub y: F8,
    /// v_a after this step's kick, x, m/s.
    pub vx: F8,
    /// v_a after the kick, y, m/s.
    pub vy: F8,
    /// ρ_a, kg/m³.
    pub rho: F8,
}

impl ContinuitySide {
    /// Particle `a` in every lane.
    #[inline(always)]
    pub fn splat(a: usize, input: &ContinuityInputs<'_>) -> ContinuitySide {
        let f = &input.fields;
        ContinuitySide {
            x: [f.pos.x[a]; 8],
            y: [f.pos.y[a]; 8],
            vx: [input.kicked_x[a]; 8],
            vy: [input.kicked_y[a]; 8],
            rho: [f.rho[a]; 8],
        }
    }

    /// Particles `a0..a0 + 8`, one a lane.
    #[inline(always)]
    pub fn eight(a0: usize, input: &ContinuityInputs<'_>) -> ContinuitySide {
        let f = &input.fields;
        ContinuitySide {
            x: run(a0, f.pos.x),
            y: run(a0, f.pos.y),
            vx: run(a0, input.kicked_x),
            vy: run(a0, input.kicked_y),
            rho: run(a0, f.rho),
        }
    }
}

/// −m (Σ x, Σ y) + g: the acceleration from the momentum terms' sums.
#[inline(always)]
pub fn acceleration(sum_x: f64, sum_y: f64, prm: &WcParams) -> DVec2 {
    -prm.mass * DVec2::new(sum_x, sum_y) + prm.gravity
}

/// (p_a/ρ_a² + p_b/ρ_b² + Π_ab) ∇_a W_ab, x and y, of the eight pairs (a in each lane of `me`,
/// b in `b`): Monaghan's Π = −α c0 μ / ρ̄ with μ = h v_ab·r_ab / (r² + 0.01 h²), as one
/// division, between fluid particles approaching each other only.
#[inline(always)]
pub fn momentum(
    me: &MomentumSide,
    b: &[usize; 8],
    keep: [bool; 8],
    f: &Fields<'_>,
    prm: &WcParams,
) -> (F8, F8) {
    let (dx, dy, r2) = separations(&me.x, &me.y, b, f.pos);
    let (rho, p) = (gather(b, f.rho), gather(b, f.p));
    let (vx, vy) = (gather(b, f.vx), gather(b, f.vy));
    let g = gradient_factors(&r2, prm);
    let (mut tx, mut ty) = ([0.0; 8], [0.0; 8]);
    for k in 0..8 {
        let mut scalar = me.own[k] + p[k] / (rho[k] * rho[k]);
        let vr = (me.vx[k] - vx[k]) * dx[k] + (me.vy[k] - vy[k]) * dy[k];
        let pi =
            prm.viscosity * vr / ((r2[k] + prm.viscosity_eps_sq) * (0.5 * (me.rho[k] + rho[k])));
        if b[k] < prm.fluid && vr < 0.0 {
            scalar += pi;
        }
        let kept = keep[k] && r2[k] < prm.support_sq;
        let sg = scalar * g[k];
        tx[k] = if kept { sg * dx[k] } else { 0.0 };
        ty[k] = if kept { sg * dy[k] } else { 0.0 };
    }
    (tx, ty)
}

/// ρ_a v_ab·∇_a W_ab / ρ_b + δ h c0 · 2 (ρ_a − ρ_b) g(r) / ρ_b (the diffusion between fluid
/// particles only) of the eight pairs, with the kicked velocities; the continuity pass's sum
/// times m is dρ_a/dt.
#[inline(always)]
pub fn continuity(
    me: &ContinuitySide,
    b: &[usize; 8],
    keep: [bool; 8],
    input: &ContinuityInputs<'_>,
    prm: &WcParams,
) -> F8 {
    let f = &input.fields;
    let diffusion = 2.0 * prm.delta * prm.h * prm.c0;
    let (dx, dy, r2) = separations(&me.x, &me.y, b, f.pos);
    let rho = gather(b, f.rho);
    let (vx, vy) = (gather(b, input.kicked_x), gather(b, input.kicked_y));
    let g = gradient_factors(&r2, prm);
    let mut term = [0.0; 8];
    for k in 0..8 {
        let vr = (me.vx[k] - vx[k]) * dx[k] + (me.vy[k] - vy[k]) * dy[k];
        let mut flux = me.rho[k] * vr;
        if b[k] < prm.fluid {
            flux += diffusion * (me.rho[k] - rho[k]);
        }
        let kept = keep[k] && r2[k] < prm.support_sq;
        term[k] = if kept { g[k] / rho[k] * flux } else { 0.0 };
    }
    term
}

/// The Wendland gradient factor of [`WcParams::gradient_factor`] for eight squared distances,
/// as the same operations (a select for its branch).
#[inline(always)]
fn gradient_factors(r2: &F8, prm: &WcParams) -> F8 {
    let mut g = [0.0; 8];
    for k in 0..8 {
        let q = r2[k].sqrt() * prm.inv_h;
        let t = 1.0 - 0.5 * q;
        let factor = -prm.gradient_norm * ((t * t) * t);
        g[k] = if q >= 2.0 { 0.0 } else { factor };
    }
    g
}

/// x_a − x_b and y_a − y_b of the eight pairs, and their squared distance: (x_b − x_a)² is
/// (x_a − x_b)², bit for bit, so it is `distance_squared`'s value.
#[inline(always)]
fn separations(xa: &F8, ya: &F8, b: &[usize; 8], pos: Positions<'_>) -> (F8, F8, F8) {
    let (x, y) = (gather(b, pos.x), gather(b, pos.y));
    let (mut dx, mut dy, mut r2) = ([0.0; 8], [0.0; 8], [0.0; 8]);
    for k in 0..8 {
        dx[k] = xa[k] - x[k];
        dy[k] = ya[k] - y[k];
        r2[k] = dx[k] * dx[k] + dy[k] * dy[k];
    }
    (dx, dy, r2)
}

/// `values` of particles `b`.
#[inline(always)]
fn gather(b: &[usize; 8], values: &[f64]) -> F8 {
    let mut out = [0.0; 8];
    for k in 0..8 {
        out[k] = values[b[k]];
    }
    out
}

/// `values` of particles `a0..a0 + 8`.
#[inline(always)]
fn run(a0: usize, values: &[f64]) -> F8 {
    values[a0..a0 + 8].try_into().expect("eight values")
}

/// Lanes `0..len` kept.
#[inline(always)]
pub fn first(len: usize) -> [bool; 8] {
    let mut keep = [false; 8];
    for (k, kept) in keep.iter_mut().enumerate() {
        *kept = k < len;
    }
    keep
}
