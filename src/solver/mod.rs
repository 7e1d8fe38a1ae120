//! One step = three passes over all particles, each handed to a strategy's executor, plus the
//! grid rebuild before them and the divergence check after them. How each pass is cut into
//! kernel calls lives in `schedule`.

mod schedule;

use sph_strategies::{Executor, KernelPanic};

use crate::sph::neighbors::{self, AnyNeighbors, NeighborLists, NeighborMode, Neighbors};
use crate::sph::params::Params;
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
#[derive(Debug, Clone)]
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
    fault: Option<usize>,
}

/// One pass of a step, for benchmarks and traces.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Pass {
    /// Density and pressure (and each particle's neighbour list).
    Density,
    /// Pressure, viscosity and gravity forces.
    Forces,
    /// Symplectic Euler and the walls.
    Integrate,
}

impl Pass {
    /// The three passes in step order.
    pub const ALL: [Pass; 3] = [Pass::Density, Pass::Forces, Pass::Integrate];

    /// Lower-case name, as in bench ids and traces.
    pub fn as_str(self) -> &'static str {
        match self {
            Pass::Density => "density",
            Pass::Forces => "forces",
            Pass::Integrate => "integrate",
        }
    }
}

/// Runs `$body` with `$nb` bound to the concrete search inside `$any`, so that the code in
/// `$body` is monomorphised per search (picked once per call, not per particle).
macro_rules! with_search {
    ($any:expr, $nb:ident => $body:expr) => {
        match $any {
            AnyNeighbors::AllPairs($nb) => $body,
            AnyNeighbors::Grid($nb) => $body,
        }
    };
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
            fault: None,
        }
    }

    /// Makes the density kernel panic when it reaches `particle` (test-only fault injection,
    /// checked once per kernel call, to exercise the strategies' panic handling end to end).
    pub fn inject_panic_at(&mut self, particle: Option<usize>) {
        self.fault = particle;
    }

    /// Runs `steps` steps on `exec`. Stops at the first failing step.
    pub fn advance<E: Executor>(&mut self, exec: &E, steps: usize) -> Result<(), StepError> {
        for _ in 0..steps {
            let step = self.steps_done + 1;
            self.step_once(exec)
                .map_err(|source| StepError::Kernel { step, source })?;
            self.steps_done = step;
            // Any non-finite density, pressure, force or position makes the particle's own
            // velocity non-finite in the same step, so checking velocities (2 arrays rather
            // than 8) catches every divergence; the full scan then names the first field.
            if !self.state.velocities_finite()
                && let Some((field, particle)) = self.state.first_non_finite()
            {
                return Err(StepError::Diverged {
                    step,
                    particle,
                    field,
                });
            }
        }
        Ok(())
    }

    /// One step without the divergence check: rebuild the search, then the three passes.
    fn step_once<E: Executor>(&mut self, exec: &E) -> Result<(), KernelPanic> {
        self.rebuild_neighbors_on(exec)?;
        Pass::ALL
            .into_iter()
            .try_for_each(|pass| self.run_pass(exec, pass))
    }

    /// Brings the neighbour search up to date with the current positions, on `exec`.
    pub fn rebuild_neighbors_on<E: Executor>(&mut self, exec: &E) -> Result<(), KernelPanic> {
        let pos = Positions {
            x: &self.state.x,
            y: &self.state.y,
        };
        with_search!(&mut self.neighbors, nb => nb.rebuild(exec, pos))
    }

    /// Brings the neighbour search up to date with the current positions, on this thread.
    pub fn rebuild_neighbors(&mut self) {
        let run = self.rebuild_neighbors_on(&sph_strategies::seq::SeqExecutor);
        // The rebuild's kernels only compute cell numbers and copy positions.
        run.expect("a sequential grid rebuild cannot panic");
    }

    /// Runs one pass over all particles on `exec`. The density pass needs an up-to-date search
    /// ([`Simulation::rebuild_neighbors`]); the force pass needs this step's densities.
    pub fn run_pass<E: Executor>(&mut self, exec: &E, pass: Pass) -> Result<(), KernelPanic> {
        let (s, prm, lists) = (&mut self.state, &self.params, &mut self.lists);
        match pass {
            Pass::Density => {
                with_search!(&self.neighbors, nb => schedule::density(exec, nb, lists, s, prm, self.fault))
            }
            Pass::Forces => {
                with_search!(&self.neighbors, nb => schedule::forces(exec, nb, lists, s, prm))
            }
            Pass::Integrate => schedule::integrate(exec, s, prm, self.domain),
        }
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
