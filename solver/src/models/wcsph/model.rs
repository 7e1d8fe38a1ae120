//! The weakly compressible model (the `wcsph` preset, see [`crate::models::wcsph`]) as the solver
//! runs it: its constants ([`WcParams`]) as a [`Model`], and its step's six passes. Fluid
//! particles are `0..fluid`, walls the rest; each pass writes its own arrays over one of the
//! two ranges.

use glam::DVec2;
use sph_strategies::{Executor, KernelPanic};

use crate::models::Preset;
use crate::models::wcsph::by_eight;
use crate::models::wcsph::kept::KeptLists;
use crate::models::wcsph::pairs::ContinuityInputs;
use crate::models::wcsph::params::{COLUMN_WIDTH, WcParams};
use crate::models::wcsph::passes::{self, Listed};
use crate::simd::Lanes;
use crate::solver::model::{self, Model, Particles, Units, no_such_pass};
use crate::solver::pass::Pass;
use crate::solver::search::{with_search, with_search_lanes};
use crate::sph::neighbors::{AnyNeighbors, GridKeys, NeighborLists, Neighbors, WCSPH_SLOTS};
use crate::sph::state::{Domain, Fields, Positions, State};
use crate::with_lanes;

/// Fluid particles per block of the largest-speed reduction.
pub const SPEED_BLOCK: usize = 256;

/// What the WCSPH step keeps besides the particle state.
#[derive(Debug, Clone)]
pub struct Scratch {
    /// dρ/dt of every fluid particle, from the continuity pass, kg/(m³ s).
    pub drho: Vec<f64>,
    /// Largest squared fluid speed per block of [`SPEED_BLOCK`] particles, m²/s².
    pub block_max: Vec<f64>,
    /// This step's time step, s.
    pub dt: f64,
    /// Velocity x of every particle after this step's kick (from the momentum pass; walls 0),
    /// m/s.
    pub kicked_x: Vec<f64>,
    /// Velocity y after the kick.
    pub kicked_y: Vec<f64>,
    /// Where the neighbour lists were built, and whether to build them again.
    pub kept: KeptLists,
}

impl Scratch {
    /// Room for `fluid` fluid particles of `n`, searched by `search`.
    pub fn new(fluid: usize, n: usize, search: &AnyNeighbors) -> Scratch {
        Scratch {
            drho: vec![0.0; fluid],
            block_max: vec![0.0; fluid.div_ceil(SPEED_BLOCK)],
            dt: 0.0,
            kicked_x: vec![0.0; n],
            kicked_y: vec![0.0; n],
            kept: with_search!(search, (nb, _lists) => KeptLists::new(n, nb)),
        }
    }
}

impl model::Scratch for Scratch {
    fn heap_bytes(&self) -> usize {
        let kicked = self.kicked_x.capacity() + self.kicked_y.capacity();
        8 * (self.drho.capacity() + self.block_max.capacity() + kicked) + self.kept.heap_bytes()
    }
}

impl Model for WcParams {
    type Scratch = Scratch;

    fn passes(&self) -> &'static [Pass] {
        &Pass::WCSPH
    }

    // The momentum and continuity passes compute eight pair terms at once on any search.
    fn lanes_on_grid(&self) -> bool {
        true
    }

    fn preset(&self) -> Preset {
        Preset::Wcsph
    }

    // The lists' radius: 2h and the skin.
    fn search_radius(&self) -> f64 {
        self.list_radius
    }

    fn fluid(&self, n: usize) -> usize {
        self.fluid.min(n)
    }

    fn wall_depth(&self) -> f64 {
        self.wall_layers() as f64 * self.dx
    }

    // Walls need lists too (of their fluid neighbours).
    fn lists(&self, n: usize) -> (usize, usize) {
        (n, WCSPH_SLOTS)
    }

    // The momentum and continuity passes read eight lists at once by slot (`by_eight`).
    fn grid_keys(&self) -> Option<GridKeys> {
        Some(GridKeys::Index)
    }

    fn units(&self) -> Units {
        Units::Si
    }

    fn drawn_radius(&self) -> f64 {
        0.5 * self.dx
    }

    // The same for every resolution, so that renders compare: a fall from the top of the
    // 2a-high column to the floor (also c0 / 10).
    fn speed_range(&self, _initial: &State) -> (f64, f64) {
        let column = 2.0 * COLUMN_WIDTH;
        (0.0, (2.0 * self.gravity.length() * column).sqrt())
    }

    // Tait's stiffness keeps the density within about 1 %.
    fn density_range(&self) -> (f64, f64) {
        (self.rho0, 1.01 * self.rho0)
    }

    fn scratch(&self, n: usize, search: &AnyNeighbors) -> Scratch {
        Scratch::new(self.fluid(n), n, search)
    }

    /// Rebuilds the search (and has the neighbour pass build the lists) only when some
    /// particle has moved half the skin since the last build ([`KeptLists`]).
    fn rebuild_search<E: Executor>(
        &self,
        exec: &E,
        on: Particles<'_>,
        scratch: &mut Scratch,
    ) -> Result<(), KernelPanic> {
        let s = &*on.state;
        let pos = Positions { x: &s.x, y: &s.y };
        let kept = &mut scratch.kept;
        let stale = with_search!(&*on.neighbors, (nb, _lists) => kept.stale(exec, pos, nb, self.relist_sq))?;
        if stale {
            with_search!(on.neighbors, (nb, _lists) => nb.rebuild(exec, pos))?;
            kept.rebuilt(exec, pos)?;
        }
        Ok(())
    }

    fn run_pass<E: Executor>(
        &self,
        exec: &E,
        pass: Pass,
        on: Particles<'_>,
        scratch: &mut Scratch,
    ) -> Result<(), KernelPanic> {
        let Particles {
            state: s,
            neighbors: nb,
            lanes,
            ..
        } = on;
        match pass {
            Pass::MaxSpeed => max_speed(exec, s, scratch, self),
            Pass::Neighbors if scratch.kept.take_relist() => {
                with_search_lanes!(nb, lanes, (nb, lists, l) => neighbors(exec, l, &*nb, lists, s, self))
            }
            // The lists still serve.
            Pass::Neighbors => Ok(()),
            Pass::Walls => {
                with_search!(nb, (nb, lists) => with_lanes!(lanes, l => walls(exec, l, Listed { nb: &*nb, lists }, s, self)))
            }
            Pass::Momentum => {
                let Scratch {
                    kicked_x,
                    kicked_y,
                    dt,
                    ..
                } = scratch;
                let kicked = (&mut kicked_x[..self.fluid], &mut kicked_y[..self.fluid]);
                with_search!(nb, (nb, lists) => with_lanes!(lanes, l => momentum(exec, l, Listed { nb: &*nb, lists }, s, kicked, *dt, self)))
            }
            Pass::Continuity => {
                let Scratch {
                    drho,
                    kicked_x,
                    kicked_y,
                    ..
                } = scratch;
                let kicked = (&kicked_x[..], &kicked_y[..]);
                with_search!(nb, (nb, lists) => with_lanes!(lanes, l => continuity(exec, l, Listed { nb: &*nb, lists }, s, kicked, drho, self)))
            }
            Pass::Integrate => integrate(exec, s, scratch, self),
            other => no_such_pass(self.preset(), other),
        }
    }

    fn list_builds(&self, scratch: &Scratch) -> Option<u64> {
        Some(scratch.kept.builds())
    }

    fn last_dt(&self, scratch: &Scratch) -> f64 {
        scratch.dt
    }

    fn fixed_dt(&self) -> Option<f64> {
        None
    }

    fn first_dt(&self) -> f64 {
        self.time_step(0.0)
    }

    /// The first fluid particle that left the tank (beyond a wall's outer face: over the top
    /// of a wall and down outside it) or whose density is not positive, and why. Either ends
    /// the dam break the model describes (the tank is open at the top), so the run stops
    /// rather than go on with a wrong number.
    fn first_unphysical(&self, s: &State, domain: Domain) -> Option<(usize, &'static str)> {
        let wall = self.wall_depth();
        let x_max = domain.width + wall;
        let fluid = self.fluid;
        let outside = |k: usize| s.x[k] < -wall || s.x[k] > x_max || s.y[k] < -wall;
        if let Some(k) = (0..fluid).find(|&k| outside(k)) {
            return Some((k, "left the tank over a wall"));
        }
        let k = s.rho[..fluid].iter().position(|&rho| rho <= 0.0)?;
        Some((k, "has a density of zero or less"))
    }
}

/// Writes each block's largest squared speed (a parallel pass over blocks), then sets
/// `scratch.dt` from their maximum (`max` is exact, so the grouping cannot change the bits).
pub fn max_speed<E: Executor>(
    exec: &E,
    s: &State,
    scratch: &mut Scratch,
    prm: &WcParams,
) -> Result<(), KernelPanic> {
    let (vx, vy) = (&s.vx[..prm.fluid], &s.vy[..prm.fluid]);
    exec.for_each_chunk(&mut scratch.block_max[..], |first, maxima| {
        for (k, m) in maxima.iter_mut().enumerate() {
            let lo = (first + k) * SPEED_BLOCK;
            let hi = (lo + SPEED_BLOCK).min(vx.len());
            *m = passes::max_speed_squared(&vx[lo..hi], &vy[lo..hi]);
        }
    })?;
    let v_max = scratch
        .block_max
        .iter()
        .fold(0.0, |m: f64, &b| m.max(b))
        .sqrt();
    scratch.dt = prm.time_step(v_max);
    Ok(())
}

/// Writes every particle's neighbour list (walls: fluid neighbours only); reads positions.
pub fn neighbors<E: Executor, N: Neighbors, L: Lanes>(
    exec: &E,
    lanes: L,
    nb: &N,
    lists: &mut NeighborLists<N::Key>,
    s: &State,
    prm: &WcParams,
) -> Result<(), KernelPanic> {
    let pos = Positions { x: &s.x, y: &s.y };
    exec.for_each_chunk(lists.split_mut(), |first, (count, mut slots)| {
        lanes.vectorize(
            #[inline(always)]
            || {
                let scratch = &mut N::Scratch::default();
                for (k, c) in count.iter_mut().enumerate() {
                    let list = slots.particle(k);
                    *c = passes::neighbors(first + k, scratch, lanes, pos, nb, prm, list);
                }
            },
        )
    })
}

/// Writes the walls' rho and p; reads the fluid's positions, rho and p and the lists. Eight
/// consecutive walls at a time where their lists allow ([`by_eight::wall_sums`]), each summing
/// its list in its order, as one alone does.
pub fn walls<E: Executor, N: Neighbors, L: Lanes>(
    exec: &E,
    lanes: L,
    listed: Listed<'_, N>,
    s: &mut State,
    prm: &WcParams,
) -> Result<(), KernelPanic> {
    let (fluid_rho, wall_rho) = s.rho.split_at_mut(prm.fluid);
    let (fluid_p, wall_p) = s.p.split_at_mut(prm.fluid);
    let f = Fields::new((&s.x, &s.y), (&s.vx, &s.vy), fluid_rho, fluid_p);
    exec.for_each_chunk((wall_rho, wall_p), |first, (rho, p)| {
        lanes.vectorize(
            #[inline(always)]
            || {
                let w0 = prm.fluid + first;
                let one = |k: usize| passes::wall_state(w0 + k, &f, &listed, prm);
                let mut k = 0;
                while k + 8 <= rho.len() {
                    match by_eight::wall_sums(w0 + k, &f, &listed, prm) {
                        Some((num, den)) => (0..8).for_each(|j| {
                            (rho[k + j], p[k + j]) = passes::wall_from_sums(num[j], den[j], prm)
                        }),
                        None => (k..k + 8).for_each(|k| (rho[k], p[k]) = one(k)),
                    }
                    k += 8;
                }
                for k in k..rho.len() {
                    (rho[k], p[k]) = one(k);
                }
            },
        )
    })
}

/// Writes the fluid's acceleration (into fx, fy) and its velocity after this step's kick
/// (into `kicked`, for the continuity pass); reads every field and the lists.
#[allow(clippy::too_many_arguments)]
pub fn momentum<E: Executor, N: Neighbors, L: Lanes>(
    exec: &E,
    lanes: L,
    listed: Listed<'_, N>,
    s: &mut State,
    kicked: (&mut [f64], &mut [f64]),
    dt: f64,
    prm: &WcParams,
) -> Result<(), KernelPanic> {
    let f = Fields::new((&s.x, &s.y), (&s.vx, &s.vy), &s.rho, &s.p);
    let out = ((&mut s.fx[..prm.fluid], &mut s.fy[..prm.fluid]), kicked);
    exec.for_each_chunk(out, |first, ((ax, ay), (kx, ky))| {
        lanes.vectorize(
            #[inline(always)]
            || {
                let len = ax.len();
                let mut write = |k: usize, a: DVec2| {
                    let i = first + k;
                    let v = passes::kick(DVec2::new(f.vx[i], f.vy[i]), a, dt);
                    (ax[k], ay[k], kx[k], ky[k]) = (a.x, a.y, v.x, v.y);
                };
                let mut k = 0;
                while k + 8 <= len {
                    match by_eight::accelerations(first + k, &f, &listed, prm) {
                        Some(a) => (0..8).for_each(|j| write(k + j, a[j])),
                        None => (k..k + 8).for_each(|k| {
                            write(k, passes::acceleration(first + k, &f, &listed, prm))
                        }),
                    }
                    k += 8;
                }
                for k in k..len {
                    write(k, passes::acceleration(first + k, &f, &listed, prm));
                }
            },
        )
    })
}

/// Writes the fluid's dρ/dt; reads every field, the kicked velocities and the lists.
pub fn continuity<E: Executor, N: Neighbors, L: Lanes>(
    exec: &E,
    lanes: L,
    listed: Listed<'_, N>,
    s: &State,
    (kicked_x, kicked_y): (&[f64], &[f64]),
    drho: &mut [f64],
    prm: &WcParams,
) -> Result<(), KernelPanic> {
    let input = ContinuityInputs {
        fields: Fields::new((&s.x, &s.y), (&s.vx, &s.vy), &s.rho, &s.p),
        kicked_x,
        kicked_y,
    };
    exec.for_each_chunk(drho, |first, drho| {
        lanes.vectorize(
            #[inline(always)]
            || {
                let len = drho.len();
                let mut k = 0;
                while k + 8 <= len {
                    match by_eight::density_sums(first + k, &input, &listed, prm) {
                        Some(sum) => (0..8).for_each(|j| drho[k + j] = prm.mass * sum[j]),
                        None => (k..k + 8).for_each(|k| {
                            drho[k] = passes::density_rate(first + k, &input, &listed, prm)
                        }),
                    }
                    k += 8;
                }
                for (k, d) in drho.iter_mut().enumerate().skip(k) {
                    *d = passes::density_rate(first + k, &input, &listed, prm);
                }
            },
        )
    })
}

/// Writes the fluid's positions, velocities, rho and p (each particle only its own).
pub fn integrate<E: Executor>(
    exec: &E,
    s: &mut State,
    scratch: &Scratch,
    prm: &WcParams,
) -> Result<(), KernelPanic> {
    let (ax, ay, drho, dt) = (&s.fx, &s.fy, &scratch.drho, scratch.dt);
    let n = prm.fluid;
    let out = (
        (&mut s.x[..n], &mut s.y[..n]),
        (&mut s.vx[..n], &mut s.vy[..n]),
        &mut s.rho[..n],
        &mut s.p[..n],
    );
    exec.for_each_chunk(out, |first, ((x, y), (vx, vy), rho, p)| {
        let fields = x.iter_mut().zip(y).zip(vx).zip(vy).zip(rho).zip(p);
        for (k, (((((x, y), vx), vy), rho), p)) in fields.enumerate() {
            let i = first + k;
            let (xn, vn, rn, pn) = passes::integrate(
                DVec2::new(*x, *y),
                DVec2::new(*vx, *vy),
                DVec2::new(ax[i], ay[i]),
                *rho,
                drho[i],
                dt,
                prm,
            );
            (*x, *y, *vx, *vy, *rho, *p) = (xn.x, xn.y, vn.x, vn.y, rn, pn);
        }
    })
}
