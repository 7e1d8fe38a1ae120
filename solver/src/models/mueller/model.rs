//! Müller's model (the `seed` and `cpp` presets) as the solver runs it: its constants
//! ([`Params`]) as a [`Model`], and its step's two passes: density, then forces with each
//! particle's update.

use glam::DVec2;
use sph_strategies::{Executor, KernelPanic};

use crate::models::mueller::next_motion::NextMotion;
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
    type Scratch = NextMotion;

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

    fn scratch(&self, n: usize, _: &AnyNeighbors) -> NextMotion {
        NextMotion::new(n)
    }

    fn run_pass<E: Executor>(
        &self,
        exec: &E,
        pass: Pass,
        on: Particles<'_>,
        next: &mut NextMotion,
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
                let moved = with_search!(nb, (nb, lists) => with_lanes!(lanes, l => {
                    forces_and_moves(exec, l, &*nb, lists, s, next, self, domain)
                }));
                // Only a finished pass moves the particles: after a kernel's panic the state
                // keeps the step's starting positions and velocities.
                moved.map(|()| next.swap_into(s))
            }
            other => no_such_pass(self.preset(), other),
        }
    }

    fn last_dt(&self, _: &NextMotion) -> f64 {
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

/// Writes fx, fy and, into `next`, each particle's position and velocity at the end of the
/// step (the symplectic Euler update and the walls, from its own force and density); reads
/// positions, velocities, rho, each particle's own p and the neighbour lists, which no chunk
/// writes. Each chunk computes its forces, then moves its particles in a loop of its own.
#[allow(clippy::too_many_arguments)]
pub fn forces_and_moves<E: Executor, N: Neighbors, L: Lanes>(
    exec: &E,
    lanes: L,
    nb: &N,
    lists: &NeighborLists<N::Key>,
    s: &mut State,
    next: &mut NextMotion,
    prm: &Params,
    domain: Domain,
) -> Result<(), KernelPanic> {
    let input = Fields::new((&s.x, &s.y), (&s.vx, &s.vy), &s.rho, &s.p);
    let forces = (&mut s.fx[..], &mut s.fy[..]);
    let moved = (
        &mut next.x[..],
        &mut next.y[..],
        &mut next.vx[..],
        &mut next.vy[..],
    );
    exec.for_each_chunk((forces, moved), |first, ((fx, fy), moved)| {
        lanes.vectorize(
            #[inline(always)]
            || {
                for (k, (fx, fy)) in fx.iter_mut().zip(fy.iter_mut()).enumerate() {
                    let i = first + k;
                    let f = passes::force(i, lanes, &input, lists.of(i), nb, prm);
                    (*fx, *fy) = (f.x, f.y);
                }
            },
        );
        let now = input.of_range(first..first + fx.len());
        move_particles(lanes, now, (fx, fy), moved, prm, domain);
    })
}

/// Moves each particle of a chunk (symplectic Euler, then the walls): `now` and the forces are
/// the chunk's, `moved` receives its new positions and velocities. Runs inside
/// [`Lanes::vectorize`], on inputs cut to one length, so that the compiler may take several
/// particles per instruction on the path's registers (the clamps are selects).
#[inline(always)]
fn move_particles<L: Lanes>(
    lanes: L,
    now: Fields<'_>,
    (fx, fy): (&[f64], &[f64]),
    (x, y, vx, vy): (&mut [f64], &mut [f64], &mut [f64], &mut [f64]),
    prm: &Params,
    domain: Domain,
) {
    lanes.vectorize(
        #[inline(always)]
        || {
            // Cut to one length, so that one bounds check covers every read and write.
            let now = now.to_common_length();
            let len = now.pos.len();
            let (fx, fy) = (&fx[..len], &fy[..len]);
            let (x, y, vx, vy) = (&mut x[..len], &mut y[..len], &mut vx[..len], &mut vy[..len]);
            for k in 0..len {
                let (p, v) = passes::integrate(
                    now.pos.at(k),
                    DVec2::new(now.vx[k], now.vy[k]),
                    DVec2::new(fx[k], fy[k]),
                    now.rho[k],
                    prm,
                    domain,
                );
                (x[k], y[k], vx[k], vy[k]) = (p.x, p.y, v.x, v.y);
            }
        },
    )
}

#[cfg(test)]
mod tests {
    use sph_strategies::seq::SeqExecutor;
    use sph_strategies::{Executor, KernelPanic, Split};

    use crate::models::Preset;
    use crate::scene::Scene;
    use crate::solver::pass::Pass;
    use crate::sph::neighbors::NeighborMode;

    /// Runs every chunk as `seq` does, then reports a kernel's panic: a pass whose kernels all
    /// wrote their outputs and still failed.
    struct FailsAfterwards;

    impl Executor for FailsAfterwards {
        fn for_each_chunk<O, F>(&self, out: O, kernel: F) -> Result<(), KernelPanic>
        where
            O: Split,
            F: Fn(usize, O) + Sync,
        {
            SeqExecutor.for_each_chunk(out, kernel)?;
            Err(KernelPanic {
                message: "injected".into(),
            })
        }

        fn threads(&self) -> usize {
            1
        }
    }

    #[test]
    fn the_force_pass_moves_the_particles_only_when_it_finishes() {
        let mut sim = Scene::dam_break(Preset::Seed, 60, 7)
            .unwrap()
            .simulate(NeighborMode::AllPairs);
        sim.advance(&SeqExecutor, 30).unwrap();
        sim.rebuild_neighbors();
        sim.run_pass(&SeqExecutor, Pass::Density).unwrap();
        let before = sim.state.clone();

        let err = sim.run_pass(&FailsAfterwards, Pass::Forces).unwrap_err();
        assert_eq!(err.message, "injected");
        let s = &sim.state;
        assert_eq!(
            (&s.x, &s.y, &s.vx, &s.vy),
            (&before.x, &before.y, &before.vx, &before.vy)
        );

        sim.run_pass(&SeqExecutor, Pass::Forces).unwrap();
        let s = &sim.state;
        assert_ne!(s.y, before.y, "a finished pass moves the falling dam");
        assert_ne!(s.vy, before.vy);
    }
}
