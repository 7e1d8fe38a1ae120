//! One step = three passes over all particles, each handed to a strategy's executor, plus the
//! grid rebuild before them and the divergence check after them.

use sph_strategies::{Executor, KernelPanic};

use crate::sph::neighbors::{self, AnyNeighbors, NeighborLists, NeighborMode, Neighbors, SlotsMut};
use crate::sph::params::Params;
use crate::sph::passes::{self, ForceInputs};
use crate::sph::state::{Domain, Positions, State};

/// Why a step failed.
#[derive(Debug, thiserror::Error)]
pub enum StepError {
    /// A value became NaN or infinite.
    #[error("the simulation diverged at step {step}: particle {particle} has a non-finite {field}")]
    Diverged {
        /// 1-based step number.
        step: usize,
        /// Index of the first particle found with a non-finite value.
        particle: usize,
        /// The field in which it was found.
        field: &'static str,
    },
    /// A kernel panicked (a bug): the state is partly updated and must be discarded.
    #[error("step {step} failed")]
    Kernel {
        /// 1-based step number.
        step: usize,
        /// The panic.
        source: KernelPanic,
    },
}

/// A running simulation: constants, walls, particles and the neighbour search.
#[derive(Debug)]
pub struct Simulation {
    /// The preset's constants.
    pub params: Params,
    /// The walls.
    pub domain: Domain,
    /// The particles.
    pub state: State,
    /// Steps completed so far.
    pub steps_done: usize,
    neighbors: AnyNeighbors,
    lists: NeighborLists,
}

impl Simulation {
    /// A simulation of `state` inside `domain` with the given constants and neighbour search.
    pub fn new(params: Params, domain: Domain, state: State, mode: NeighborMode) -> Self {
        let neighbors = neighbors::build(mode, domain, params.h, state.len());
        let lists = NeighborLists::new(state.len());
        Simulation {
            params,
            domain,
            state,
            steps_done: 0,
            neighbors,
            lists,
        }
    }

    /// Runs `steps` steps on `exec`. Stops at the first failing step.
    pub fn advance<E: Executor>(&mut self, exec: &E, steps: usize) -> Result<(), StepError> {
        for _ in 0..steps {
            let step = self.steps_done + 1;
            // The search is picked once per step; the passes are monomorphised per search.
            let (lists, state, prm, domain) =
                (&mut self.lists, &mut self.state, &self.params, self.domain);
            match &mut self.neighbors {
                AnyNeighbors::AllPairs(nb) => step_once(exec, nb, lists, state, prm, domain),
                AnyNeighbors::Grid(nb) => step_once(exec, nb, lists, state, prm, domain),
            }
            .map_err(|source| StepError::Kernel { step, source })?;
            self.steps_done = step;
            if let Some((field, particle)) = self.state.first_non_finite() {
                return Err(StepError::Diverged {
                    step,
                    particle,
                    field,
                });
            }
        }
        Ok(())
    }

    /// Bytes held by the neighbour search and lists, for memory reports.
    pub fn neighbor_heap_bytes(&self) -> usize {
        self.lists.heap_bytes()
            + match &self.neighbors {
                AnyNeighbors::AllPairs(_) => 0,
                AnyNeighbors::Grid(g) => g.heap_bytes(),
            }
    }
}

/// Density and pressure, then forces, then integration, each pass over all particles.
fn step_once<E: Executor, N: Neighbors>(
    exec: &E,
    nb: &mut N,
    lists: &mut NeighborLists,
    s: &mut State,
    prm: &Params,
    domain: Domain,
) -> Result<(), KernelPanic> {
    nb.rebuild(Positions { x: &s.x, y: &s.y });
    let nb = &*nb;
    let pos = Positions { x: &s.x, y: &s.y };

    let out = (
        &mut s.rho[..],
        &mut s.p[..],
        &mut lists.count[..],
        SlotsMut(&mut lists.slots[..]),
    );
    exec.for_each_chunk(out, |first, (rho, p, count, mut slots)| {
        for (k, ((rho, p), count)) in rho.iter_mut().zip(p).zip(count).enumerate() {
            (*rho, *p, *count) =
                passes::density_pressure(first + k, pos, nb, prm, slots.particle(k));
        }
    })?;

    let lists = &*lists;
    let input = ForceInputs {
        pos,
        vx: &s.vx,
        vy: &s.vy,
        rho: &s.rho,
        p: &s.p,
    };
    exec.for_each_chunk((&mut s.fx[..], &mut s.fy[..]), |first, (fx, fy)| {
        for (k, (fx, fy)) in fx.iter_mut().zip(fy).enumerate() {
            let i = first + k;
            let f = passes::force(i, &input, lists.of(i), nb, prm);
            (*fx, *fy) = (f.x, f.y);
        }
    })?;

    let (fx, fy, rho) = (&s.fx, &s.fy, &s.rho);
    let out = (&mut s.x[..], &mut s.y[..], &mut s.vx[..], &mut s.vy[..]);
    exec.for_each_chunk(out, |first, (x, y, vx, vy)| {
        for (k, (((x, y), vx), vy)) in x.iter_mut().zip(y).zip(vx).zip(vy).enumerate() {
            let i = first + k;
            let f = glam::DVec2::new(fx[i], fy[i]);
            let (p, v) = passes::integrate(
                glam::DVec2::new(*x, *y),
                glam::DVec2::new(*vx, *vy),
                f,
                rho[i],
                prm,
                domain,
            );
            (*x, *y, *vx, *vy) = (p.x, p.y, v.x, v.y);
        }
    })
}
