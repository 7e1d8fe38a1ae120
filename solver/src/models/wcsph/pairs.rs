//! The momentum and continuity pair terms of eight (or sixteen) pairs at once, lane by lane, as the same
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
//! The arrays of lanes are written as plain loops, and the neighbours' fields gathered into
//! arrays first (`Neighbours`), so that the compiler runs the arithmetic in whole registers
//! of the run's SIMD path (inside [`crate::simd::Lanes::vectorize`]); `array::map` and
//! `array::from_fn` were left as calls there. A lane's conditions select, or mask to +0
//! (`or_zero`), rather than branch around the arithmetic.

use glam::DVec2;

use super::params::WcParams;
use crate::sph::state::Fields;

/// Eight lanes.
pub type F8 = [f64; 8];

/// `W` lanes: eight, or sixteen for two pairs of each of eight particles at once (the
/// continuity pass in [`super::by_eight`]).
pub type Lanes<const W: usize> = [f64; W];

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
pub struct MomentumSide<const W: usize = 8> {
    /// x_a, m.
    pub x: Lanes<W>,
    /// y_a, m.
    pub y: Lanes<W>,
    /// v_a, x, m/s.
    pub vx: Lanes<W>,
    /// v_a, y, m/s.
    pub vy: Lanes<W>,
    /// ρ_a, kg/m³.
    pub rho: Lanes<W>,
    /// p_a/ρ_a², m⁵/(kg s²).
    pub own: Lanes<W>,
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
pub struct ContinuitySide<const W: usize = 8> {
    /// x_a, m.
    pub x: Lanes<W>,
    /// y_a, m.
    pub y: Lanes<W>,
    /// v_a after this step's kick, x, m/s.
    pub vx: Lanes<W>,
    /// v_a after the kick, y, m/s.
    pub vy: Lanes<W>,
    /// ρ_a, kg/m³.
    pub rho: Lanes<W>,
}

impl ContinuitySide<16> {
    /// Particles `a0..a0 + 8`, one a lane, twice: lanes k and 8 + k hold particle a0 + k.
    #[inline(always)]
    pub fn eight_twice(a0: usize, input: &ContinuityInputs<'_>) -> ContinuitySide<16> {
        let me = ContinuitySide::eight(a0, input);
        ContinuitySide {
            x: twice(&me.x),
            y: twice(&me.y),
            vx: twice(&me.vx),
            vy: twice(&me.vy),
            rho: twice(&me.rho),
        }
    }
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
pub fn momentum<const W: usize>(
    me: &MomentumSide<W>,
    b: &[usize; W],
    keep: [bool; W],
    f: &Fields<'_>,
    prm: &WcParams,
) -> (Lanes<W>, Lanes<W>) {
    let b = Neighbours(*b);
    let [x, y, vx, vy, rho, p] = b.gather([f.pos.x, f.pos.y, f.vx, f.vy, f.rho, f.p]);
    let (dx, dy, r2) = separations(&me.x, &me.y, &x, &y);
    let g = gradient_factors(&r2, prm);
    let (mut tx, mut ty) = ([0.0; W], [0.0; W]);
    for k in 0..W {
        let scalar = me.own[k] + p[k] / (rho[k] * rho[k]);
        let vr = (me.vx[k] - vx[k]) * dx[k] + (me.vy[k] - vy[k]) * dy[k];
        let pi =
            prm.viscosity * vr / ((r2[k] + prm.viscosity_eps_sq) * (0.5 * (me.rho[k] + rho[k])));
        // Short-circuit `&&` here: with `&` the pass took 410–430 ms per 1500 steps at R = 40,
        // against 330 ms (the compiler's choice; the bits are the same either way).
        let viscous = b.0[k] < prm.fluid && vr < 0.0;
        let scalar = if viscous { scalar + pi } else { scalar };
        let kept = keep[k] && r2[k] < prm.support_sq;
        let sg = scalar * g[k];
        tx[k] = or_zero(kept, sg * dx[k]);
        ty[k] = or_zero(kept, sg * dy[k]);
    }
    (tx, ty)
}

/// ρ_a v_ab·∇_a W_ab / ρ_b + δ h c0 · 2 (ρ_a − ρ_b) g(r) / ρ_b (the diffusion between fluid
/// particles only) of the eight pairs, with the kicked velocities; the continuity pass's sum
/// times m is dρ_a/dt.
#[inline(always)]
pub fn continuity<const W: usize>(
    me: &ContinuitySide<W>,
    b: &[usize; W],
    keep: [bool; W],
    input: &ContinuityInputs<'_>,
    prm: &WcParams,
) -> Lanes<W> {
    let f = &input.fields;
    let diffusion = 2.0 * prm.delta * prm.h * prm.c0;
    let b = Neighbours(*b);
    let [x, y, vx, vy, rho] = b.gather([f.pos.x, f.pos.y, input.kicked_x, input.kicked_y, f.rho]);
    let (dx, dy, r2) = separations(&me.x, &me.y, &x, &y);
    let g = gradient_factors(&r2, prm);
    let mut term = [0.0; W];
    for k in 0..W {
        let vr = (me.vx[k] - vx[k]) * dx[k] + (me.vy[k] - vy[k]) * dy[k];
        let flux = me.rho[k] * vr;
        let diffused = flux + diffusion * (me.rho[k] - rho[k]);
        let flux = if b.0[k] < prm.fluid { diffused } else { flux };
        let kept = keep[k] & (r2[k] < prm.support_sq);
        term[k] = or_zero(kept, g[k] / rho[k] * flux);
    }
    term
}

/// The wall term of eight pairs (wall particle w in each lane of `xw`, `yw`, fluid particle f
/// in `b`): (p_f + ρ_f g·r_wf) W_wf and W_wf, the terms of [`super::passes::wall_state`]'s two
/// sums. `f` holds the fluid's ρ and p only.
#[inline(always)]
pub fn wall(
    (xw, yw): (&F8, &F8),
    b: &[usize; 8],
    keep: [bool; 8],
    f: &Fields<'_>,
    prm: &WcParams,
) -> (F8, F8) {
    // A lane past its list may hold a wall's index, past the fluid's fields: it reads
    // particle 0 instead, fluid wherever a wall has a fluid neighbour to sum.
    let mut fluid = [0; 8];
    for k in 0..8 {
        fluid[k] = if keep[k] { b[k] } else { 0 };
    }
    let b = Neighbours(fluid);
    let [x, y] = b.gather([f.pos.x, f.pos.y]);
    let (dx, dy, r2) = separations(xw, yw, &x, &y);
    let [rho, p] = b.gather([f.rho, f.p]);
    let (mut num, mut den) = ([0.0; 8], [0.0; 8]);
    for k in 0..8 {
        let q = r2[k].sqrt() * prm.inv_h;
        let t = 1.0 - 0.5 * q;
        let t2 = t * t;
        let kernel = prm.kernel_norm * (t2 * t2) * (2.0 * q + 1.0);
        // `WcParams::kernel`'s zero at q ≥ 2 adds ±0 to the sums, as a lane left out does.
        let kept = keep[k] & (r2[k] < prm.support_sq) & (q < 2.0);
        let lift = prm.gravity.x * dx[k] + prm.gravity.y * dy[k];
        num[k] = or_zero(kept, (p[k] + rho[k] * lift) * kernel);
        den[k] = or_zero(kept, kernel);
    }
    (num, den)
}

/// The Wendland gradient factor of [`WcParams::gradient_factor`] for eight squared distances,
/// as the same operations (a select for its branch).
#[inline(always)]
fn gradient_factors<const W: usize>(r2: &Lanes<W>, prm: &WcParams) -> Lanes<W> {
    let mut g = [0.0; W];
    for k in 0..W {
        let q = r2[k].sqrt() * prm.inv_h;
        let t = 1.0 - 0.5 * q;
        let factor = -prm.gradient_norm * ((t * t) * t);
        g[k] = if q >= 2.0 { 0.0 } else { factor };
    }
    g
}

/// x_a − x_b and y_a − y_b of the eight pairs (b's coordinates in `xb`, `yb`), and their
/// squared distance: (x_b − x_a)² is (x_a − x_b)², bit for bit, so it is `distance_squared`'s
/// value.
#[inline(always)]
fn separations<const W: usize>(
    xa: &Lanes<W>,
    ya: &Lanes<W>,
    xb: &Lanes<W>,
    yb: &Lanes<W>,
) -> (Lanes<W>, Lanes<W>, Lanes<W>) {
    let (mut dx, mut dy, mut r2) = ([0.0; W], [0.0; W], [0.0; W]);
    for k in 0..W {
        dx[k] = xa[k] - xb[k];
        dy[k] = ya[k] - yb[k];
        r2[k] = dx[k] * dx[k] + dy[k] * dy[k];
    }
    (dx, dy, r2)
}

/// The neighbours of the lanes, one a lane, from which the passes gather their fields. The
/// fields a pass reads are cut to one length, so that each lane's index is bounds-checked once
/// for all of them, before that lane's loads: the checks keep the loads scalar (checking every
/// index before any load let the compiler fetch a field's lanes with one gather instruction,
/// `vgatherqpd`, and the continuity pass in sixteen lanes took 360–440 ms per 1500 steps at
/// R = 40 so, against 275 ms with the loads checked one by one).
struct Neighbours<const W: usize>([usize; W]);

impl<const W: usize> Neighbours<W> {
    /// The lanes' neighbours' values in each of `fields` (one value per particle, all of the
    /// first field's length).
    #[inline(always)]
    fn gather<const F: usize>(&self, fields: [&[f64]; F]) -> [Lanes<W>; F] {
        let n = fields.first().map_or(0, |f| f.len());
        let fields = fields.map(|f| &f[..n]);
        let mut out = [[0.0; W]; F];
        for k in 0..W {
            let j = self.0[k];
            for (lanes, field) in out.iter_mut().zip(&fields) {
                lanes[k] = field[j];
            }
        }
        out
    }
}

/// `x` when `kept`, else +0: as a mask on its bits, which the compiler cannot turn back into a
/// branch around the arithmetic that made `x`.
#[inline(always)]
fn or_zero(kept: bool, x: f64) -> f64 {
    f64::from_bits(x.to_bits() & (kept as u64).wrapping_neg())
}

/// Eight lanes twice over.
#[inline(always)]
fn twice(v: &F8) -> Lanes<16> {
    let mut out = [0.0; 16];
    out[..8].copy_from_slice(v);
    out[8..].copy_from_slice(v);
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
