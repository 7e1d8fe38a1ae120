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

use super::pairs::{self, ContinuityInputs, ContinuitySide, MomentumSide};
use super::params::WcParams;
use crate::sph::neighbors::{ListWriter, NeighborLists, Neighbors, distance_squared};
use crate::sph::state::{Fields, Positions};

/// The largest squared speed among the given velocities (0 for none), m²/s². `max` is exact
/// whatever the order, so blocks may be reduced in any grouping.
#[inline]
pub fn max_speed_squared(vx: &[f64], vy: &[f64]) -> f64 {
    vx.iter()
        .zip(vy)
        .fold(0.0, |m: f64, (&x, &y)| m.max(x * x + y * y))
}

/// Particle `i`'s neighbours within the lists' radius (2h and the skin, see
/// [`crate::models::wcsph::kept`]), in the search's visit order: for a fluid particle every
/// other particle, for a wall particle the fluid ones only (walls never read walls).
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
        prm.list_radius_sq,
        #[inline(always)]
        |j, _, key| {
            list.push(key, j != i && j < limit);
        },
    );
    list.finish()
}

/// The search and its lists: what a pass needs to visit a particle's neighbours.
#[derive(Debug)]
pub struct Listed<'a, N: Neighbors> {
    /// The search, as last rebuilt.
    pub nb: &'a N,
    /// Every particle's list, built at the search's last rebuild with the lists' radius.
    pub lists: &'a NeighborLists<N::Key>,
}

/// Calls `pair(b, r2)` for each of particle `i`'s neighbours now within 2h (`r2` at `pos`, the
/// positions now), in the order its list holds them: those of its list ([`for_each_in_list`])
/// now within 2h.
#[inline(always)]
fn for_each_neighbor<N: Neighbors>(
    i: usize,
    pos: Positions<'_>,
    listed: &Listed<'_, N>,
    prm: &WcParams,
    mut pair: impl FnMut(usize, f64),
) {
    let (xi, yi) = (pos.x[i], pos.y[i]);
    for_each_in_list(i, pos, listed, prm, |b| {
        let r2 = distance_squared(xi, yi, pos.x[b], pos.y[b]);
        if r2 < prm.support_sq {
            pair(b, r2);
        }
    });
}

/// Calls `visit(b)` for each particle b of particle `i`'s list, in its order (the search's
/// visit order: by index, or the grid's candidate order in its cell at the rebuild under
/// `--order cell`): the list when it fit (in its slots, and its keys in their type). Else the
/// search is asked again, with the lists' radius, for i at `pos`, the positions now: all-pairs
/// tests the others at `pos` too, the grid its copies of where they were at the rebuild, among
/// the candidates of i's cell then, in the same order. Each way visits every particle now
/// within 2h of i, none having moved half the skin since the rebuild
/// ([`crate::models::wcsph::kept`]), in the list's order, and the passes sum only those: the
/// same bits.
#[inline(always)]
fn for_each_in_list<N: Neighbors>(
    i: usize,
    pos: Positions<'_>,
    listed: &Listed<'_, N>,
    prm: &WcParams,
    mut visit: impl FnMut(usize),
) {
    match listed.lists.of(i) {
        Some(list) => listed.nb.for_each_listed(i, pos, list, visit),
        None => {
            let limit = if i < prm.fluid { usize::MAX } else { prm.fluid };
            // An unusable list (too long for its slots, or a grid key past 255) is rare: the
            // portable lanes serve (same hits).
            let scratch = &mut N::Scratch::default();
            let hsq = prm.list_radius_sq;
            listed
                .nb
                .for_each_within(scratch, Portable, i, pos, hsq, |b, _, _| {
                    if b != i && b < limit {
                        visit(b);
                    }
                });
        }
    }
}

/// Calls `eight(b, len)` for particle `i`'s listed neighbours eight at a time, in the order
/// [`for_each_neighbor`] visits them: `b[..len]` are the next `len` of them (eight but in the
/// last call), the other lanes hold `i`. Each lane is a neighbour of the lists' radius; a pass
/// computes its pair term in all eight lanes at once, as the same scalar operations, takes
/// zero for a lane past `len` or with `r2` at or beyond 2h, and adds the lanes in order: a
/// zero changes no sum (a sum from +0 is never −0), so the bits are those of the pairs
/// within 2h summed one by one.
#[inline(always)]
fn for_each_eight<N: Neighbors>(
    i: usize,
    pos: Positions<'_>,
    listed: &Listed<'_, N>,
    prm: &WcParams,
    mut eight: impl FnMut(&[usize; 8], usize),
) {
    let mut batch = Eight { b: [i; 8], len: 0 };
    for_each_in_list(
        i,
        pos,
        listed,
        prm,
        #[inline(always)]
        |j| batch.push(j, &mut eight),
    );
    if batch.len > 0 {
        batch.b[batch.len..].fill(i);
        eight(&batch.b, batch.len);
    }
}

/// The neighbours of [`for_each_eight`] not yet handed on.
struct Eight {
    b: [usize; 8],
    len: usize,
}

impl Eight {
    /// Adds `j`, and hands on all eight when they are eight.
    #[inline(always)]
    fn push(&mut self, j: usize, eight: &mut impl FnMut(&[usize; 8], usize)) {
        self.b[self.len] = j;
        self.len += 1;
        if self.len == 8 {
            eight(&self.b, 8);
            self.len = 0;
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
    listed: &Listed<'_, N>,
    prm: &WcParams,
) -> (f64, f64) {
    let xw = f.pos.at(w);
    let (mut num, mut den) = (0.0, 0.0);
    for_each_neighbor(w, f.pos, listed, prm, |j, r2| {
        let kernel = prm.kernel(r2);
        let r_wf = xw - f.pos.at(j);
        num += (f.p[j] + f.rho[j] * prm.gravity.dot(r_wf)) * kernel;
        den += kernel;
    });
    wall_from_sums(num, den, prm)
}

/// (ρ_w, p_w) from the sums of [`wall_state`]: p_w = num / den clipped at ≥ 0, 0 with no fluid
/// near.
#[inline(always)]
pub fn wall_from_sums(num: f64, den: f64, prm: &WcParams) -> (f64, f64) {
    let p = if den > 0.0 { (num / den).max(0.0) } else { 0.0 };
    (prm.density(p), p)
}

/// Acceleration of fluid particle `a` at this step's positions, velocities and densities:
/// dv_a/dt = −Σ_b m (p_a/ρ_a² + p_b/ρ_b² + Π_ab) ∇_a W_ab + g, with Monaghan's artificial
/// viscosity Π_ab = −α c0 μ_ab / ρ̄_ab, μ_ab = h v_ab·r_ab / (r² + 0.01 h²), where
/// v_ab·r_ab < 0, between fluid particles only.
#[inline(always)]
pub fn acceleration<N: Neighbors>(
    a: usize,
    f: &Fields<'_>,
    listed: &Listed<'_, N>,
    prm: &WcParams,
) -> DVec2 {
    let me = MomentumSide::splat(a, f);
    let (mut sx, mut sy) = (0.0, 0.0);
    for_each_eight(
        a,
        f.pos,
        listed,
        prm,
        #[inline(always)]
        |b, len| {
            let (tx, ty) = pairs::momentum(&me, b, pairs::first(len), f, prm);
            for k in 0..len {
                sx += tx[k];
                sy += ty[k];
            }
        },
    );
    pairs::acceleration(sx, sy, prm)
}

/// The rate of change of fluid particle `a`'s density, with the kicked velocities:
/// dρ_a/dt = Σ_b m (ρ_a/ρ_b) v_ab·∇_a W_ab + δ h c0 Σ_b (m/ρ_b) ψ_ab·∇_a W_ab, with
/// ψ_ab = 2 (ρ_a − ρ_b) r_ab / |r_ab|² (Molteni & Colagrossi 2009) over fluid neighbours
/// only; since r_ab·r_ab = |r_ab|², ψ_ab·∇_a W_ab = 2 (ρ_a − ρ_b) g(r). kg/(m³ s).
#[inline(always)]
pub fn density_rate<N: Neighbors>(
    a: usize,
    input: &ContinuityInputs<'_>,
    listed: &Listed<'_, N>,
    prm: &WcParams,
) -> f64 {
    let me = ContinuitySide::splat(a, input);
    let mut sum = 0.0;
    for_each_eight(
        a,
        input.fields.pos,
        listed,
        prm,
        #[inline(always)]
        |b, len| {
            let term = pairs::continuity(&me, b, pairs::first(len), input, prm);
            for &t in &term[..len] {
                sum += t;
            }
        },
    );
    prm.mass * sum
}

/// v + dt·a: the kick, in the one grouping that the momentum pass (for the continuity pass)
/// and [`integrate`] share.
#[inline(always)]
pub fn kick(v: DVec2, a: DVec2, dt: f64) -> DVec2 {
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
