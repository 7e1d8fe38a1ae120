//! What a step of Müller's model (the `seed` and `cpp` presets) computes for each particle —
//! density and pressure, force, and the update, run in two passes — each a pure function of
//! one particle and read-only state (Müller, Charypar & Gross 2003, as the seed and C++
//! sources evaluate it; operation order is part of the contract — see the book's "Physics"
//! page, book/src/physics.md). No threads, clocks, I/O or allocation here: the solver decides
//! which particles each call covers.

use glam::DVec2;

use super::params::{Integrator, Params};
use crate::simd::{F64x4, Lanes};
use crate::sph::neighbors::{ListWriter, Neighbors, distance_squared};
use crate::sph::state::{Domain, Fields, Positions};

/// Density (Müller 2003 eq. 3 with the poly6 kernel, eq. 20; self term included) and
/// pressure `GAS_CONST · (rho − REST_DENS)` (eq. 12) of particle `i`, plus the number of its
/// neighbours j ≠ i. Candidates are tested in `lanes` (every path finds the same).
///
/// Contributions `(MASS·POLY6) · ((u·u)·u)`, `u = HSQ − r2`, are summed in the search's visit
/// order (index order unless a grid in cell order) from 0, or in eight lanes where the search
/// sums in lanes ([`Neighbors::sums_in_lanes`]: the grid in cell order in a small run; see
/// `density_in_lanes`). The neighbours j ≠ i are written to `list` in that order; the returned
/// count is its [`ListWriter::finish`]. `scratch` is the search's working memory (see
/// [`Neighbors::Scratch`]).
#[inline(always)]
pub fn density_pressure<N: Neighbors>(
    i: usize,
    scratch: &mut N::Scratch,
    lanes: impl Lanes,
    pos: Positions<'_>,
    nb: &N,
    prm: &Params,
    mut list: ListWriter<'_, N::Key>,
) -> (f64, f64, u32) {
    if nb.sums_in_lanes() {
        let rho = density_in_lanes(i, scratch, lanes, pos, nb, prm, &mut list);
        return (rho, pressure(rho, prm), list.finish());
    }
    let mut rho = 0.0;
    nb.for_each_within(
        scratch,
        lanes,
        i,
        pos,
        prm.hsq,
        #[inline(always)]
        |j, r2, key| {
            let u = prm.hsq - r2;
            rho += prm.mass_poly6 * ((u * u) * u);
            list.push(key, j != i);
        },
    );
    let count = list.finish();
    (rho, pressure(rho, prm), count)
}

/// Pressure from density, `GAS_CONST · (rho − REST_DENS)` (Müller 2003 eq. 12), as the density
/// pass stores it. The force pass computes each neighbour's pressure again from its density
/// rather than reading it: the same bits, and one array fewer to fetch, on two or more threads,
/// from the core that wrote it.
#[inline(always)]
fn pressure(rho: f64, prm: &Params) -> f64 {
    prm.gas_const * (rho - prm.rest_density)
}

/// The density of [`density_pressure`] summed in eight lanes: each lane's contributions in
/// order from 0, then the lanes added in a fixed tree, lane k to lane k + 4, those four sums k
/// to k + 2, then the two: `((s0 + s4) + (s2 + s6)) + ((s1 + s5) + (s3 + s7))`. Each
/// contribution has the bits the scalar formula gives it; only the order of the additions
/// differs.
///
/// A lane without a hit adds +0, which changes no sum (each is +0 or more): `u = max(hsq − r2,
/// +0)` is +0 there (r2 ≥ hsq, +∞ in a lane without a candidate, or NaN), and a hit's u is
/// hsq − r2 itself. Lanes that pack hits in registers (AVX-512) take a row's eight candidates
/// at once ([`Neighbors::for_each_eight`]), the others one candidate at a time into its lane
/// ([`Neighbors::for_each_in_lanes`]), which measured faster there: both add the same
/// contributions to the same lanes in the same order, so every path gives the same bits.
#[inline(always)]
fn density_in_lanes<N: Neighbors, L: Lanes>(
    i: usize,
    scratch: &mut N::Scratch,
    lanes: L,
    pos: Positions<'_>,
    nb: &N,
    prm: &Params,
    list: &mut ListWriter<'_, N::Key>,
) -> f64 {
    if !L::PACKS_HITS {
        let mut sums = [0.0f64; 8];
        nb.for_each_in_lanes(
            scratch,
            lanes,
            i,
            pos,
            prm.hsq,
            #[inline(always)]
            |lane, j, r2, key| {
                // As `positive` (`Quad::positive4`) computes it.
                let d = prm.hsq - r2;
                let u = if d > 0.0 { d } else { 0.0 };
                // lane < 8: the mask spares a bounds check.
                sums[lane & 7] += prm.mass_poly6 * ((u * u) * u);
                list.push(key, r2 < prm.hsq && j != i);
            },
        );
        let [s0, s1, s2, s3, s4, s5, s6, s7] = sums;
        return ((s0 + s4) + (s2 + s6)) + ((s1 + s5) + (s3 + s7));
    }
    // The eight sums in two vectors of four.
    let zero = F64x4::new(lanes, [0.0; 4]);
    let hsq = F64x4::new(lanes, [prm.hsq; 4]);
    let mut sums = [zero; 2];
    nb.for_each_eight(
        scratch,
        lanes,
        i,
        pos,
        prm.hsq,
        #[inline(always)]
        |eight| {
            let (fours, _) = eight.r2.as_chunks::<4>();
            for (sum, &r2) in sums.iter_mut().zip(fours) {
                let u = (hsq - F64x4::new(lanes, r2)).positive();
                *sum = *sum + prm.mass_poly6 * ((u * u) * u);
            }
            let keep = eight.within & lanes.ne8(eight.j, i as u32);
            list.push_eight(&eight.key, &lanes.compress8(eight.key, keep), keep);
        },
    );
    let [[s04, s15], [s26, s37]] = (sums[0] + sums[1]).halves();
    (s04 + s26) + (s15 + s37)
}

/// Force on particle `i` from this step's densities and i's own pressure in `input`: pressure
/// (Müller 2003 eq. 10 with the spiky gradient, eq. 21) plus viscosity (eq. 14 with the
/// viscosity Laplacian, eq. 22) over j ≠ i with `r < H`, in the search's visit order (index
/// order unless a grid in cell order), plus `G · rho_i`. A neighbour's pressure is computed
/// from its density (`pressure`, below), not read.
///
/// Two particles at the same point (r = 0, j ≠ i) have no pressure direction: that term is
/// zero there (the Haskell source divides by zero), the viscosity term is still added.
///
/// `neighbors` is particle i's list from the density pass when it fit in its slots and its
/// keys fit their type; without
/// it the search is asked again. Both give the same j in the same order.
///
/// On a path whose vectors hold four lanes ([`Quad::TWO_NEIGHBORS`](crate::simd::Quad::TWO_NEIGHBORS)) a listed particle's
/// neighbours are taken two at a time (`add_two_pair_forces`), with the same bits.
#[inline(always)]
pub fn force<N: Neighbors, L: Lanes>(
    i: usize,
    lanes: L,
    input: &Fields<'_>,
    neighbors: Option<&[N::Key]>,
    nb: &N,
    prm: &Params,
) -> DVec2 {
    let input = &input.to_common_length();
    let me = Particle {
        x: input.pos.at(i),
        v: DVec2::new(input.vx[i], input.vy[i]),
        p: input.p[i],
    };
    let mut acc = (DVec2::ZERO, DVec2::ZERO);
    match neighbors {
        Some(list) if L::TWO_NEIGHBORS => {
            let mut held = None;
            nb.for_each_listed(
                i,
                input.pos,
                list,
                #[inline(always)]
                |j| match held.take() {
                    None => held = Some(j),
                    Some(a) => add_two_pair_forces(lanes, &mut acc, &me, (a, j), input, prm),
                },
            );
            if let Some(j) = held {
                let r2 = distance_squared(me.x.x, me.x.y, input.pos.x[j], input.pos.y[j]);
                add_pair_force(&mut acc, &me, j, r2, input, prm);
            }
        }
        Some(list) => nb.for_each_listed(
            i,
            input.pos,
            list,
            #[inline(always)]
            |j| {
                let r2 = distance_squared(me.x.x, me.x.y, input.pos.x[j], input.pos.y[j]);
                add_pair_force(&mut acc, &me, j, r2, input, prm);
            },
        ),
        None => {
            // Rare (a pile), so its working memory is made here.
            let scratch = &mut N::Scratch::default();
            nb.for_each_within(scratch, lanes, i, input.pos, prm.hsq, |j, r2, _| {
                if j != i {
                    add_pair_force(&mut acc, &me, j, r2, input, prm);
                }
            });
        }
    }
    let (fpress, fvisc) = acc;
    (fpress + fvisc) + prm.gravity * input.rho[i]
}

/// What the force pass needs of particle i.
struct Particle {
    x: DVec2,
    v: DVec2,
    p: f64,
}

/// Adds neighbour j's pressure and viscosity terms to `(fpress, fvisc)` when `r < H`.
#[inline(always)]
fn add_pair_force(
    acc: &mut (DVec2, DVec2),
    me: &Particle,
    j: usize,
    r2: f64,
    input: &Fields<'_>,
    prm: &Params,
) {
    // r2 < HSQ can still round to r = H: the sources decide on r.
    let r = r2.sqrt();
    if r < prm.h {
        let d = input.pos.at(j) - me.x;
        let rho_j = input.rho[j];
        let p_j = pressure(rho_j, prm);
        let hr = prm.h - r;
        if r > 0.0 {
            acc.0 += ((((-d / r) * prm.mass) * (me.p + p_j)) / (2.0 * rho_j))
                * prm.spiky_grad
                * (hr * hr);
        }
        let vj = DVec2::new(input.vx[j], input.vy[j]);
        acc.1 += (((prm.visc_mass * (vj - me.v)) / rho_j) * prm.visc_lap) * hr;
    }
}

/// Adds neighbour a's terms and then b's, as [`add_pair_force`] would one after the other,
/// computing both at once: x and y of each in four lanes (`F64x4`), the same operations lane by
/// lane, so the same bits. A pair at r = H (r2 < HSQ rounded up) or at r = 0 (two particles at
/// one point) is left to [`add_pair_force`].
#[inline(always)]
fn add_two_pair_forces<L: Lanes>(
    lanes: L,
    acc: &mut (DVec2, DVec2),
    me: &Particle,
    (a, b): (usize, usize),
    input: &Fields<'_>,
    prm: &Params,
) {
    let pos = input.pos;
    let r2 = [a, b].map(|j| distance_squared(me.x.x, me.x.y, pos.x[j], pos.y[j]));
    let [ra, rb] = lanes.sqrt2(r2);
    let inside = |r: f64| r < prm.h && r > 0.0;
    if !(inside(ra) && inside(rb)) {
        add_pair_force(acc, me, a, r2[0], input, prm);
        add_pair_force(acc, me, b, r2[1], input, prm);
        return;
    }
    // `halves(u, v)`: u in a's lanes, v in b's.
    let halves = |u, v| F64x4::halves_of(lanes, u, v);
    let pairs = |u: DVec2, v: DVec2| F64x4::pairs(lanes, u.to_array(), v.to_array());
    let mine = pairs(me.x, me.x);
    let d = pairs(pos.at(a), pos.at(b)) - mine;
    let (hra, hrb) = (prm.h - ra, prm.h - rb);
    let (rho_a, rho_b) = (input.rho[a], input.rho[b]);
    let fpress = ((((-d / halves(ra, rb)) * prm.mass)
        * halves(me.p + pressure(rho_a, prm), me.p + pressure(rho_b, prm)))
        / halves(2.0 * rho_a, 2.0 * rho_b))
        * prm.spiky_grad
        * halves(hra * hra, hrb * hrb);
    let velocity = |j: usize| DVec2::new(input.vx[j], input.vy[j]);
    let dv = pairs(velocity(a), velocity(b)) - pairs(me.v, me.v);
    let fvisc = (((prm.visc_mass * dv) / halves(rho_a, rho_b)) * prm.visc_lap) * halves(hra, hrb);
    let ([pa, pb], [va, vb]) = (fpress.halves(), fvisc.halves());
    acc.0 += DVec2::from_array(pa);
    acc.1 += DVec2::from_array(va);
    acc.0 += DVec2::from_array(pb);
    acc.1 += DVec2::from_array(vb);
}

/// Symplectic Euler step of one particle followed by the wall clamps; returns the new
/// (position, velocity).
///
/// A component beyond `EPS` of a wall is put back at `EPS` and its velocity multiplied by
/// `BOUND_DAMPING`.
#[inline(always)]
pub fn integrate(
    x: DVec2,
    v: DVec2,
    f: DVec2,
    rho: f64,
    prm: &Params,
    domain: Domain,
) -> (DVec2, DVec2) {
    let mut v = match prm.integrator {
        Integrator::Seed => v + prm.dt * (f / rho),
        Integrator::Cpp => v + (prm.dt * f) / rho,
    };
    let mut x = x + prm.dt * v;
    let (eps, damping) = (prm.eps, prm.bound_damping);
    // Each clamp as selects, not branches, in the same order (the upper wall's test sees the
    // lower's result): the same bits, and a loop over particles the compiler can vectorise.
    let clamp = |beyond: bool, coord: &mut f64, speed: &mut f64, to: f64| {
        *speed = if beyond { *speed * damping } else { *speed };
        *coord = if beyond { to } else { *coord };
    };
    let walls = |coord: &mut f64, speed: &mut f64, extent: f64| {
        clamp(*coord - eps < 0.0, coord, speed, eps);
        clamp(*coord + eps > extent, coord, speed, extent - eps);
    };
    walls(&mut x.x, &mut v.x, domain.width);
    walls(&mut x.y, &mut v.y, domain.height);
    (x, v)
}
