//! Müller's model (the `seed` and `cpp` presets) as the solver runs it: its constants
//! ([`Params`]) as a [`Model`], and its step's three passes.

use glam::DVec2;
use sph_strategies::{Executor, KernelPanic};

use crate::models::mueller::passes;
use crate::models::{
    Preset,
    mueller::params::{Integrator, Params},
};
use crate::simd::Lanes;
use crate::solver::model::{Model, Particles, Units, no_such_pass};
use crate::solver::pass::Pass;
use crate::solver::search::{with_search, with_search_lanes};
use crate::sph::neighbors::{AnyNeighbors, NeighborLists, Neighbors, SLOTS};
use crate::sph::state::{Domain, Fields, Positions, State};
use crate::with_lanes;

impl Model for Params {
    type Scratch = ();

    fn passes(&self) -> &'static [Pass] {
        &Pass::MUELLER
    }

    // The force pass searches only for a pile, and takes two neighbours at once on any search.
    fn lanes_on_grid(&self) -> bool {
        true
    }

    fn preset(&self) -> Preset {
        match self.integrator {
            Integrator::Seed => Preset::Seed,
            Integrator::Cpp => Preset::Cpp,
        }
    }

    fn search_radius(&self) -> f64 {
        self.h
    }

    fn fluid(&self, n: usize) -> usize {
        n
    }

    fn wall_depth(&self) -> f64 {
        0.0
    }

    fn lists(&self, n: usize) -> (usize, usize) {
        (n, SLOTS)
    }

    fn units(&self) -> Units {
        Units::Pixels
    }

    fn drawn_radius(&self) -> f64 {
        0.5 * self.h
    }

    // A particle falling freely from the top of the initial dam to the floor.
    fn speed_range(&self, initial: &State) -> (f64, f64) {
        let top = initial.y.iter().copied().fold(self.eps, f64::max);
        let fall = top - self.eps;
        (0.0, (2.0 * self.gravity.length() * fall).sqrt())
    }

    // A particle with no neighbours (its own contribution) to four times that.
    fn density_range(&self) -> (f64, f64) {
        let own = self.mass_poly6 * ((self.hsq * self.hsq) * self.hsq);
        (own, 4.0 * own)
    }

    fn scratch(&self, _: usize, _: &AnyNeighbors) {}

    fn run_pass<E: Executor>(
        &self,
        exec: &E,
        pass: Pass,
        on: Particles<'_>,
        _: &mut (),
    ) -> Result<(), KernelPanic> {
        let Particles {
            state: s,
            neighbors: nb,
            lanes,
            domain,
        } = on;
        match pass {
            Pass::Density => {
                with_search_lanes!(nb, lanes, (nb, lists, l) => density(exec, l, &*nb, lists, s, self))
            }
            Pass::Forces => {
                with_search!(nb, (nb, lists) => with_lanes!(lanes, l => forces(exec, l, &*nb, lists, s, self)))
            }
            Pass::Integrate => with_lanes!(lanes, l => integrate(exec, l, s, self, domain)),
            other => no_such_pass(self.preset(), other),
        }
    }

    fn last_dt(&self, _: &()) -> f64 {
        self.dt
    }

    fn fixed_dt(&self) -> Option<f64> {
        Some(self.dt)
    }

    fn first_dt(&self) -> f64 {
        self.dt
    }
}

/// Writes rho, p and the neighbour lists; reads positions.
pub fn density<E: Executor, N: Neighbors, L: Lanes>(
    exec: &E,
    lanes: L,
    nb: &N,
    lists: &mut NeighborLists<N::Key>,
    s: &mut State,
    prm: &Params,
) -> Result<(), KernelPanic> {
    let pos = Positions { x: &s.x, y: &s.y };
    let (count, slots) = lists.split_mut();
    let out = (&mut s.rho[..], &mut s.p[..], count, slots);
    exec.for_each_chunk(out, |first, (rho, p, count, mut slots)| {
        lanes.vectorize(
            #[inline(always)]
            || {
                let scratch = &mut N::Scratch::default();
                for (k, ((rho, p), count)) in rho.iter_mut().zip(p).zip(count).enumerate() {
                    let list = slots.particle(k);
                    (*rho, *p, *count) =
                        passes::density_pressure(first + k, scratch, lanes, pos, nb, prm, list);
                }
            },
        )
    })
}

/// Writes fx, fy; reads positions, velocities, rho, p and the neighbour lists.
pub fn forces<E: Executor, N: Neighbors, L: Lanes>(
    exec: &E,
    lanes: L,
    nb: &N,
    lists: &NeighborLists<N::Key>,
    s: &mut State,
    prm: &Params,
) -> Result<(), KernelPanic> {
    let input = Fields::new((&s.x, &s.y), (&s.vx, &s.vy), &s.rho, &s.p);
    exec.for_each_chunk((&mut s.fx[..], &mut s.fy[..]), |first, (fx, fy)| {
        lanes.vectorize(
            #[inline(always)]
            || {
                for (k, (fx, fy)) in fx.iter_mut().zip(fy).enumerate() {
                    let i = first + k;
                    let f = passes::force(i, lanes, &input, lists.of(i), nb, prm);
                    (*fx, *fy) = (f.x, f.y);
                }
            },
        )
    })
}

/// Writes positions and velocities (each particle only its own); reads fx, fy, rho. Runs inside
/// [`Lanes::vectorize`], on inputs cut to each chunk's length, so that the compiler may take
/// several particles per instruction on the path's registers (the clamps are selects).
pub fn integrate<E: Executor, L: Lanes>(
    exec: &E,
    lanes: L,
    s: &mut State,
    prm: &Params,
    domain: Domain,
) -> Result<(), KernelPanic> {
    let (fx, fy, rho) = (&s.fx[..], &s.fy[..], &s.rho[..]);
    let out = (&mut s.x[..], &mut s.y[..], &mut s.vx[..], &mut s.vy[..]);
    exec.for_each_chunk(out, |first, (x, y, vx, vy)| {
        let len = x.len();
        let (fx, fy, rho) = (
            &fx[first..][..len],
            &fy[first..][..len],
            &rho[first..][..len],
        );
        lanes.vectorize(
            #[inline(always)]
            || {
                // Cut to one length, so that one bounds check covers every read and write.
                let (y, vx, vy) = (&mut y[..len], &mut vx[..len], &mut vy[..len]);
                for k in 0..len {
                    let (p, v) = passes::integrate(
                        DVec2::new(x[k], y[k]),
                        DVec2::new(vx[k], vy[k]),
                        DVec2::new(fx[k], fy[k]),
                        rho[k],
                        prm,
                        domain,
                    );
                    (x[k], y[k], vx[k], vy[k]) = (p.x, p.y, v.x, v.y);
                }
            },
        )
    })
}
