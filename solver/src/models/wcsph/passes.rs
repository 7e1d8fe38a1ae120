//! The passes of one weakly compressible step, each a pure function of one particle and
//! read-only state. Sums run over the neighbours in increasing index order (fluid first, then
//! walls, as the state stores them), so every strategy and both searches give the same bits
//! (the grid in `--order cell` visits them in the order it finds them instead: its own bits,
//! the same on every strategy).
//!
//! Notation: r_ab = x_a − x_b, v_ab = v_a − v_b, ∇_a W_ab = g(r) r_ab with
//! g = [`WcParams::gradient_factor`].

use crate::simd::{Lanes, Portable};
use glam::DVec2;

use super::params::WcParams;
use crate::sph::neighbors::{ListWriter, Neighbors, distance_squared};
use crate::sph::state::{Fields, Positions};

/// The largest squared speed among the given velocities (0 for none), m²/s². `max` is exact
/// whatever the order, so blocks may be reduced in any grouping.
#[inline]
pub fn max_speed_squared(vx: &[f64], vy: &[f64]) -> f64 {
    vx.iter()
        .zip(vy)
        .fold(0.0, |m: f64, (&x, &y)| m.max(x * x + y * y))
}

/// Particle `i`'s neighbours within the kernel support, in the search's visit order: for a fluid particle
/// every other particle, for a wall particle the fluid ones only (walls never read walls).
///
/// They are written to `list`; the returned count is its [`ListWriter::finish`] (see
/// [`crate::sph::neighbors::NeighborLists`]).
#[inline(always)]
pub fn neighbors<N: Neighbors>(
    i: usize,
    scratch: &mut N::Scratch,
    lanes: impl Lanes,
    pos: Positions<'_>,
    nb: &N,
    prm: &WcParams,
    mut list: ListWriter<'_, N::Key>,
) -> u32 {
    let limit = if i < prm.fluid { usize::MAX } else { prm.fluid };
    nb.for_each_within(
        scratch,
        lanes,
        i,
        pos,
        prm.support_sq,
        #[inline(always)]
        |j, _, key| {
            list.push(key, j != i && j < limit);
        },
    );
    list.finish()
}

/// Calls `pair(b, r2)` for each of particle `i`'s neighbours ([`neighbors`]) in visit order:
/// from its list when it fit (in its slots, and its keys in their type), else by asking the
/// search again.
#[inline(always)]
fn for_each_neighbor<N: Neighbors>(
    i: usize,
    pos: Positions<'_>,
    list: Option<&[N::Key]>,
    nb: &N,
    prm: &WcParams,
    mut pair: impl FnMut(usize, f64),
) {
    let (xi, yi) = (pos.x[i], pos.y[i]);
    match list {
        Some(list) => nb.for_each_listed(
            i,
            pos,
            list,
            #[inline(always)]
            |b| {
                pair(b, distance_squared(xi, yi, pos.x[b], pos.y[b]));
            },
        ),
        None => {
            let limit = if i < prm.fluid { usize::MAX } else { prm.fluid };
            // An unusable list (too long for its slots, or a grid key past 255) is rare: the
            // portable lanes serve (same hits).
            let scratch = &mut N::Scratch::default();
            nb.for_each_within(scratch, Portable, i, pos, prm.support_sq, |b, r2, _| {
                if b != i && b < limit {
                    pair(b, r2);
                }
            });
        }
    }
}

/// Pressure and density of wall particle `w` (Adami, Hu & Adams 2012, eq. 27 for a wall at
/// rest): p_w = Σ_f (p_f + ρ_f g·r_wf) W_wf / Σ_f W_wf over the fluid neighbours, clipped at
/// ≥ 0 (0 with no fluid near), and ρ_w from the inverse equation of state. Returns (ρ_w, p_w).
#[inline]
pub fn wall_state<N: Neighbors>(
    w: usize,
    f: &Fields<'_>,
    list: Option<&[N::Key]>,
    nb: &N,
    prm: &WcParams,
) -> (f64, f64) {
    let xw = f.pos.at(w);
    let (mut num, mut den) = (0.0, 0.0);
    for_each_neighbor(w, f.pos, list, nb, prm, |j, r2| {
        let kernel = prm.kernel(r2);
        let r_wf = xw - f.pos.at(j);
        num += (f.p[j] + f.rho[j] * prm.gravity.dot(r_wf)) * kernel;
        den += kernel;
    });
    let p = if den > 0.0 { (num / den).max(0.0) } else { 0.0 };
    (prm.density(p), p)
}

/// Acceleration of fluid particle `a` at this step's positions, velocities and densities:
/// dv_a/dt = −Σ_b m (p_a/ρ_a² + p_b/ρ_b² + Π_ab) ∇_a W_ab + g, with Monaghan's artificial
/// viscosity Π_ab = −α c0 μ_ab / ρ̄_ab, μ_ab = h v_ab·r_ab / (r² + 0.01 h²), where
/// v_ab·r_ab < 0, between fluid particles only.
#[inline]
pub fn acceleration<N: Neighbors>(
    a: usize,
    f: &Fields<'_>,
    list: Option<&[N::Key]>,
    nb: &N,
    prm: &WcParams,
) -> DVec2 {
    let me = Me::of(a, f);
    let own = me.p / (me.rho * me.rho);
    let mut sum = DVec2::ZERO;
    for_each_neighbor(a, f.pos, list, nb, prm, |b, r2| {
        sum += momentum_term(&me, own, b, r2, f, prm);
    });
    -prm.mass * sum + prm.gravity
}

/// What the pair terms need of particle a.
struct Me {
    x: DVec2,
    v: DVec2,
    rho: f64,
    p: f64,
}

impl Me {
    #[inline(always)]
    fn of(a: usize, f: &Fields<'_>) -> Me {
        Me {
            x: f.pos.at(a),
            v: DVec2::new(f.vx[a], f.vy[a]),
            rho: f.rho[a],
            p: f.p[a],
        }
    }
}

/// (p_a/ρ_a² + p_b/ρ_b² + Π_ab) ∇_a W_ab for neighbour b at squared distance `r2`.
#[inline(always)]
fn momentum_term(me: &Me, own: f64, b: usize, r2: f64, f: &Fields<'_>, prm: &WcParams) -> DVec2 {
    let r_ab = me.x - f.pos.at(b);
    let (rho_b, p_b) = (f.rho[b], f.p[b]);
    let mut scalar = own + p_b / (rho_b * rho_b);
    if b < prm.fluid {
        let v_ab = me.v - DVec2::new(f.vx[b], f.vy[b]);
        let vr = v_ab.dot(r_ab);
        if vr < 0.0 {
            // Π = −α c0 μ / ρ̄ with μ = h v·r / (r² + 0.01 h²), as one division.
            scalar += prm.viscosity * vr / ((r2 + prm.viscosity_eps_sq) * (0.5 * (me.rho + rho_b)));
        }
    }
    (scalar * prm.gradient_factor(r2)) * r_ab
}

/// Read-only inputs of the continuity pass: the fields at the start of the step and this
/// step's accelerations, from which the kicked velocities v + dt·a are recomputed exactly
/// as [`integrate`] computes them.
#[derive(Debug, Clone, Copy)]
pub struct ContinuityInputs<'a> {
    /// The fields at the start of the step.
    pub fields: Fields<'a>,
    /// Acceleration x of every fluid particle, m/s².
    pub ax: &'a [f64],
    /// Acceleration y.
    pub ay: &'a [f64],
    /// This step's time step, s.
    pub dt: f64,
}

impl ContinuityInputs<'_> {
    /// Particle b's velocity after this step's kick (walls stay at rest).
    #[inline(always)]
    fn kicked(&self, b: usize, fluid: usize) -> DVec2 {
        if b < fluid {
            kick(
                DVec2::new(self.fields.vx[b], self.fields.vy[b]),
                DVec2::new(self.ax[b], self.ay[b]),
                self.dt,
            )
        } else {
            DVec2::ZERO
        }
    }
}

/// The rate of change of fluid particle `a`'s density, with the kicked velocities:
/// dρ_a/dt = Σ_b m (ρ_a/ρ_b) v_ab·∇_a W_ab + δ h c0 Σ_b (m/ρ_b) ψ_ab·∇_a W_ab, with
/// ψ_ab = 2 (ρ_a − ρ_b) r_ab / |r_ab|² (Molteni & Colagrossi 2009) over fluid neighbours
/// only; since r_ab·r_ab = |r_ab|², ψ_ab·∇_a W_ab = 2 (ρ_a − ρ_b) g(r). kg/(m³ s).
#[inline]
pub fn density_rate<N: Neighbors>(
    a: usize,
    input: &ContinuityInputs<'_>,
    list: Option<&[N::Key]>,
    nb: &N,
    prm: &WcParams,
) -> f64 {
    let f = &input.fields;
    let x_a = f.pos.at(a);
    let v_a = input.kicked(a, prm.fluid);
    let rho_a = f.rho[a];
    let diffusion = 2.0 * prm.delta * prm.h * prm.c0;
    let mut sum = 0.0;
    for_each_neighbor(a, f.pos, list, nb, prm, |b, r2| {
        let r_ab = x_a - f.pos.at(b);
        let v_ab = v_a - input.kicked(b, prm.fluid);
        let rho_b = f.rho[b];
        let mut flux = rho_a * v_ab.dot(r_ab);
        if b < prm.fluid {
            flux += diffusion * (rho_a - rho_b);
        }
        sum += prm.gradient_factor(r2) / rho_b * flux;
    });
    prm.mass * sum
}

/// v + dt·a: the kick, in the one grouping that the continuity pass and [`integrate`] share.
#[inline(always)]
fn kick(v: DVec2, a: DVec2, dt: f64) -> DVec2 {
    v + dt * a
}

/// One fluid particle's step: kick v with the acceleration, update ρ with its rate (which
/// used the kicked velocities) and p from ρ, then drift x with the kicked velocity. Returns
/// (x, v, ρ, p).
#[inline]
pub fn integrate(
    x: DVec2,
    v: DVec2,
    a: DVec2,
    rho: f64,
    drho: f64,
    dt: f64,
    prm: &WcParams,
) -> (DVec2, DVec2, f64, f64) {
    let v = kick(v, a, dt);
    let rho = rho + dt * drho;
    (x + dt * v, v, rho, prm.pressure(rho))
}
