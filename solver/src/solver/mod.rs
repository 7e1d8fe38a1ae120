//! One step = the model's passes over the particles, each handed to a strategy's executor, plus the
//! grid rebuild before them and the divergence check after them: two passes for Müller's model
//! (density; forces, which also move each particle), six for WCSPH (max speed, neighbours, walls,
//! momentum, continuity, integrate). What the solver asks of a model is [`model::Model`]; the
//! registry of models is [`crate::models::Physics`], and how each model cuts its passes into kernel
//! calls lives in its folder of `crate::models`; here is the one step loop
//! ([`Simulation::advance_with`]) and the [`StepHooks`] through which a caller wraps each phase's
//! executor (tracing, fault injection) or the check, in `step`.

pub mod model;
pub mod pass;
pub(crate) mod search;
mod step;

pub use crate::models::wcsph::model::SPEED_BLOCK;
pub use pass::Pass;
pub use step::{Phase, PhaseJob, StepHooks};

use sph_strategies::{Executor, KernelPanic};

use crate::models::{Physics, with_model};
use crate::simd::{self, AnyLanes, SimdPath};
use crate::solver::model::{AnyScratch, Model, Particles};
use crate::solver::search::with_search;
use crate::sph::neighbors::{
    self, AnyNeighbors, CellOrderNeedsGrid, GridKeys, NeighborMode, SumOrder,
};
use crate::sph::state::{Domain, State};

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
    /// The run left what its model describes (`wcsph`: a fluid particle outside the tank or
    /// with a density of zero or less).
    #[error(
        "the run left its model at step {step}: fluid particle {particle} {what} (a shorter \
         --t-end or --steps stays within it)"
    )]
    Unphysical {
        /// 1-based step number.
        step: usize,
        /// Index of the first such particle.
        particle: usize,
        /// What happened to it.
        what: &'static str,
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
    /// The model and its constants.
    pub physics: Physics,
    /// The walls (for WCSPH, the inner faces of the walls' particle layers).
    pub domain: Domain,
    /// The particles (for WCSPH, the fluid then the walls' fixed particles).
    pub state: State,
    /// Steps completed so far.
    pub steps_done: usize,
    /// Simulated time: the sum of the steps' time steps, s.
    pub time_s: f64,
    neighbors: AnyNeighbors,
    lanes: AnyLanes,
    scratch: AnyScratch,
}

impl Simulation {
    /// A simulation of `state` inside `domain` with the given constants and neighbour search.
    pub fn new(
        physics: impl Into<Physics>,
        domain: Domain,
        state: State,
        mode: NeighborMode,
    ) -> Self {
        let physics = physics.into();
        let n = state.len();
        let bounds = physics.search_bounds(domain);
        let lists = with_model!(physics, m => m.lists(n));
        let radius = physics.search_radius();
        let neighbors = neighbors::build(mode, bounds, radius, n, lists);
        let neighbors = match with_model!(&physics, m => m.grid_keys()) {
            Some(keys) => neighbors.with_grid_keys(keys),
            None => neighbors,
        };
        let scratch = with_model!(&physics, m => AnyScratch::of_model(m, n, &neighbors));
        Simulation {
            physics,
            domain,
            state,
            steps_done: 0,
            time_s: 0.0,
            neighbors,
            lanes: simd::current()
                .lanes()
                .expect("the current SIMD path was checked available"),
            scratch,
        }
    }

    /// The same simulation with its neighbour tests on `path` instead of the process's
    /// [`simd::current`] path (the results are the same bits).
    ///
    /// # Errors
    /// If this CPU cannot run `path`.
    pub fn with_simd(mut self, path: SimdPath) -> Result<Self, simd::Unavailable> {
        self.lanes = path.lanes().ok_or(simd::Unavailable(path))?;
        Ok(self)
    }

    /// The same simulation with `width` neighbour slots per particle instead of its model's
    /// (see [`neighbors::NeighborLists`]): the results are the same bits, only speed and memory differ
    /// (tests and benchmarks use it to show that).
    ///
    /// # Panics
    /// If `width` is 0 (the last slot is scratch).
    pub fn with_list_slots(mut self, width: usize) -> Self {
        assert!(width >= 1, "a neighbour list needs its scratch slot");
        self.neighbors.with_list_slots(width);
        self.search_replaced();
        self
    }

    /// The same simulation with its sums over neighbours in `order` ([`SumOrder`]): cell order
    /// is faster on the grid but does not give the sources' bits.
    ///
    /// # Errors
    /// Cell order with all-pairs, which has no cells.
    pub fn with_sum_order(mut self, order: SumOrder) -> Result<Self, CellOrderNeedsGrid> {
        self.neighbors = self.neighbors.with_sum_order(order)?;
        self.search_replaced();
        Ok(self)
    }

    /// Forgets what the model kept of the search it had (`wcsph`'s lists), so that the next
    /// step builds them for the new one.
    fn search_replaced(&mut self) {
        let n = self.state.len();
        self.scratch = with_model!(&self.physics, m => AnyScratch::of_model(m, n, &self.neighbors));
    }

    /// The order sums over neighbours run in.
    pub fn sum_order(&self) -> SumOrder {
        self.neighbors.sum_order()
    }

    /// The same simulation with the grid's neighbour lists in `keys` instead of the ones its
    /// size gets ([`GridKeys::for_lists`]); all-pairs is left as it is. The results are the
    /// same bits, only speed and memory differ (tests use it to run both keys at any size).
    pub fn with_grid_keys(mut self, keys: GridKeys) -> Self {
        self.neighbors = self.neighbors.with_grid_keys(keys);
        self.search_replaced();
        self
    }

    /// How the grid's neighbour lists name neighbours; `None` for all-pairs.
    pub fn grid_keys(&self) -> Option<GridKeys> {
        self.neighbors.grid_keys()
    }

    /// The SIMD path the run's vector code runs on, so that `--json` and `meta.json` name
    /// what ran: the chosen one for all-pairs' neighbour tests, for Müller's force pass (two
    /// neighbours at once), for `wcsph`'s momentum and continuity passes (eight pairs at once)
    /// and for the grid's packed scan (AVX-512).
    pub fn simd(&self) -> SimdPath {
        let on_grid = with_model!(&self.physics, m => m.lanes_on_grid());
        match (&self.neighbors, on_grid, self.lanes.path()) {
            (AnyNeighbors::AllPairs(_), _, path)
            | (_, true, path)
            | (_, _, path @ SimdPath::Avx512) => path,
            _ => SimdPath::Portable,
        }
    }

    /// The model's passes, in step order.
    pub fn passes(&self) -> &'static [Pass] {
        self.physics.passes()
    }

    /// Particles that move: the first `fluid()` of the state (the rest are walls).
    pub fn fluid(&self) -> usize {
        self.physics.fluid(self.state.len())
    }

    /// Particles whose neighbour list did not fit its slots when it was last written (their
    /// passes search again: slower, the same bits).
    pub fn unlisted(&self) -> usize {
        with_search!(&self.neighbors, (_nb, lists) => lists.unusable())
    }

    /// Times the neighbour lists were built so far where the model keeps them from step to
    /// step (`wcsph`); `None` where they are built every step.
    pub fn list_builds(&self) -> Option<u64> {
        with_model!(&self.physics, m => m.list_builds(self.scratch.of()))
    }

    /// The time step of the last step (WCSPH's adapts to the flow), s.
    pub fn last_dt(&self) -> f64 {
        with_model!(&self.physics, m => m.last_dt(self.scratch.of()))
    }

    /// Brings the neighbour search up to date with the current positions, on `exec`.
    pub fn rebuild_neighbors_on<E: Executor>(&mut self, exec: &E) -> Result<(), KernelPanic> {
        let (physics, on, scratch) = self.parts();
        with_model!(physics, m => m.rebuild_search(exec, on, scratch.of_mut()))
    }

    /// The model, what its passes run over, and its scratch, borrowed apart.
    fn parts(&mut self) -> (&Physics, Particles<'_>, &mut AnyScratch) {
        let on = Particles {
            state: &mut self.state,
            neighbors: &mut self.neighbors,
            lanes: self.lanes,
            domain: self.domain,
        };
        (&self.physics, on, &mut self.scratch)
    }

    /// Brings the neighbour search up to date with the current positions, on this thread.
    pub fn rebuild_neighbors(&mut self) {
        let run = self.rebuild_neighbors_on(&sph_strategies::seq::SeqExecutor);
        // The rebuild's kernels only compute cell numbers and copy positions.
        run.expect("a sequential grid rebuild cannot panic");
    }

    /// Runs one pass of the model on `exec`, passes in [`Simulation::passes`] order: each
    /// needs an up-to-date search ([`Simulation::rebuild_neighbors`]) and what the passes
    /// before it in the step wrote.
    ///
    /// # Panics
    /// If `pass` is not one of the model's passes.
    pub fn run_pass<E: Executor>(&mut self, exec: &E, pass: Pass) -> Result<(), KernelPanic> {
        let (physics, on, scratch) = self.parts();
        with_model!(physics, m => m.run_pass(exec, pass, on, scratch.of_mut()))
    }

    /// Bytes held by the neighbour search, lists and the model's scratch arrays, for memory
    /// reports.
    pub fn neighbor_heap_bytes(&self) -> usize {
        self.neighbors.heap_bytes() + self.scratch.heap_bytes()
    }
}
