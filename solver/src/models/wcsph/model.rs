//! The weakly compressible model (the `wcsph` preset, see [`crate::models::wcsph`]) as the solver
//! runs it: its constants ([`WcParams`]) as a [`Model`], and its step's six passes. Fluid
//! particles are `0..fluid`, walls the rest; each pass writes its own arrays over one of the
//! two ranges.

use glam::DVec2;
use sph_strategies::{Executor, KernelPanic};

use crate::models::Preset;
use crate::models::wcsph::params::{COLUMN_WIDTH, WcParams};
use crate::models::wcsph::passes::{self, ContinuityInputs};
use crate::simd::Lanes;
use crate::solver::model::{self, Model, Particles, Units, no_such_pass};
use crate::solver::pass::Pass;
use crate::solver::search::{with_search, with_search_lanes};
use crate::sph::neighbors::{NeighborLists, Neighbors, WCSPH_SLOTS};
use crate::sph::state::{Domain, Fields, Positions, State};

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
}

impl Scratch {
    /// Room for `fluid` fluid particles.
    pub fn new(fluid: usize) -> Scratch {
        Scratch {
            drho: vec![0.0; fluid],
            block_max: vec![0.0; fluid.div_ceil(SPEED_BLOCK)],
            dt: 0.0,
        }
    }
}

impl model::Scratch for Scratch {
    fn heap_bytes(&self) -> usize {
        8 * (self.drho.capacity() + self.block_max.capacity())
    }
}

impl Model for WcParams {
    type Scratch = Scratch;

    fn passes(&self) -> &'static [Pass] {
        &Pass::WCSPH
    }

    fn lanes_on_grid(&self) -> bool {
        false
    }

    fn preset(&self) -> Preset {
        Preset::Wcsph
    }

    fn search_radius(&self) -> f64 {
        self.support
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

    fn scratch(&self, n: usize) -> Scratch {
        Scratch::new(self.fluid(n))
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
            Pass::Neighbors => {
                with_search_lanes!(nb, lanes, (nb, lists, l) => neighbors(exec, l, &*nb, lists, s, self))
            }
            Pass::Walls => with_search!(nb, (nb, lists) => walls(exec, &*nb, lists, s, self)),
            Pass::Momentum => with_search!(nb, (nb, lists) => momentum(exec, &*nb, lists, s, self)),
            Pass::Continuity => {
                with_search!(nb, (nb, lists) => continuity(exec, &*nb, lists, s, scratch, self))
            }
            Pass::Integrate => integrate(exec, s, scratch, self),
            other => no_such_pass(self.preset(), other),
        }
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

/// Writes the walls' rho and p; reads the fluid's positions, rho and p and the lists.
pub fn walls<E: Executor, N: Neighbors>(
    exec: &E,
    nb: &N,
    lists: &NeighborLists<N::Key>,
    s: &mut State,
    prm: &WcParams,
) -> Result<(), KernelPanic> {
    let (fluid_rho, wall_rho) = s.rho.split_at_mut(prm.fluid);
    let (fluid_p, wall_p) = s.p.split_at_mut(prm.fluid);
    let f = Fields::new((&s.x, &s.y), (&s.vx, &s.vy), fluid_rho, fluid_p);
    exec.for_each_chunk((wall_rho, wall_p), |first, (rho, p)| {
        for (k, (rho, p)) in rho.iter_mut().zip(p).enumerate() {
            let w = prm.fluid + first + k;
            (*rho, *p) = passes::wall_state(w, &f, lists.of(w), nb, prm);
        }
    })
}

/// Writes the fluid's acceleration (into fx, fy); reads every field and the lists.
pub fn momentum<E: Executor, N: Neighbors>(
    exec: &E,
    nb: &N,
    lists: &NeighborLists<N::Key>,
    s: &mut State,
    prm: &WcParams,
) -> Result<(), KernelPanic> {
    let f = Fields::new((&s.x, &s.y), (&s.vx, &s.vy), &s.rho, &s.p);
    let out = (&mut s.fx[..prm.fluid], &mut s.fy[..prm.fluid]);
    exec.for_each_chunk(out, |first, (ax, ay)| {
        for (k, (ax, ay)) in ax.iter_mut().zip(ay).enumerate() {
            let a = passes::acceleration(first + k, &f, lists.of(first + k), nb, prm);
            (*ax, *ay) = (a.x, a.y);
        }
    })
}

/// Writes the fluid's dρ/dt; reads every field, the accelerations and the lists.
pub fn continuity<E: Executor, N: Neighbors>(
    exec: &E,
    nb: &N,
    lists: &NeighborLists<N::Key>,
    s: &State,
    scratch: &mut Scratch,
    prm: &WcParams,
) -> Result<(), KernelPanic> {
    let input = ContinuityInputs {
        fields: Fields::new((&s.x, &s.y), (&s.vx, &s.vy), &s.rho, &s.p),
        ax: &s.fx,
        ay: &s.fy,
        dt: scratch.dt,
    };
    exec.for_each_chunk(&mut scratch.drho[..], |first, drho| {
        for (k, d) in drho.iter_mut().enumerate() {
            let a = first + k;
            *d = passes::density_rate(a, &input, lists.of(a), nb, prm);
        }
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
