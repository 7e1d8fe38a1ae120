//! What the solver asks of a model of the fluid. A model is its constants (a type that
//! implements [`Model`]: Müller's `Params`, WCSPH's `WcParams`), its per-particle passes
//! (`passes.rs` in its folder of `crate::models`) and its schedule (`model.rs` there: which
//! arrays each pass writes, and the pass handed to the strategy's executor). The solver runs a
//! step through this trait and never names a model; `crate::models::Physics` lists the models.

use std::any::Any;
use std::fmt::Debug;

use sph_strategies::{Executor, KernelPanic};

use super::pass::Pass;
use crate::models::Preset;
use crate::simd::AnyLanes;
use crate::solver::search::with_search;
use crate::sph::neighbors::{AnyNeighbors, GridKeys, Neighbors};
use crate::sph::state::{Domain, Positions, State};

/// The units a model computes in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Units {
    /// Müller's presets: lengths in px, densities in the solver's own units.
    Pixels,
    /// `wcsph`: m, s, kg.
    Si,
}

/// A model of the fluid, as its constants.
pub trait Model: Copy + Debug {
    /// What a running simulation of the model keeps between passes besides the particles.
    type Scratch: Scratch;

    /// The passes of one step, in step order.
    fn passes(&self) -> &'static [Pass];

    /// Whether every pass runs on the run's SIMD path on the grid as well (Müller's force
    /// pass does), rather than only all-pairs' neighbour tests and AVX-512's packed scan.
    fn lanes_on_grid(&self) -> bool;

    /// The preset these constants belong to.
    fn preset(&self) -> Preset;

    /// The neighbour search radius.
    fn search_radius(&self) -> f64;

    /// Particles that move, of `n` (the rest are fixed walls).
    fn fluid(&self, n: usize) -> usize;

    /// How far outside the domain the walls' particles lie (left, right and below).
    fn wall_depth(&self) -> f64;

    /// The neighbour lists of `n` particles: how many particles have one, and its slots.
    fn lists(&self, n: usize) -> (usize, usize);

    /// The keys the grid's lists hold, where the model needs one kind (`wcsph`'s passes read
    /// their lists as indices); `None` lets the run's size choose ([`GridKeys::for_lists`]).
    fn grid_keys(&self) -> Option<GridKeys> {
        None
    }

    /// The units the model computes in.
    fn units(&self) -> Units;

    /// The radius a picture draws a particle with, model units: half the spacing of the
    /// initial layout, so that neighbours touch.
    fn drawn_radius(&self) -> f64;

    /// The speeds a picture colours against, from 0 to that of a fall from the top of the
    /// fluid to the floor (the fluid of `initial`, or of the model's own fixed scene).
    fn speed_range(&self, initial: &State) -> (f64, f64);

    /// The densities a picture colours against.
    fn density_range(&self) -> (f64, f64);

    /// The scratch of a run of `n` particles searched by `search`.
    fn scratch(&self, n: usize, search: &AnyNeighbors) -> Self::Scratch;

    /// Brings the neighbour search up to date with the positions of `on` (once per step,
    /// before the passes), on `exec`. By default it is rebuilt; a model whose lists outlive a
    /// step rebuilds it only when they are built again (`wcsph`'s kept lists).
    fn rebuild_search<E: Executor>(
        &self,
        exec: &E,
        on: Particles<'_>,
        scratch: &mut Self::Scratch,
    ) -> Result<(), KernelPanic> {
        let _ = scratch;
        let pos = Positions {
            x: &on.state.x,
            y: &on.state.y,
        };
        with_search!(on.neighbors, (nb, _lists) => nb.rebuild(exec, pos))
    }

    /// Runs `pass` on `exec` over `on`: each pass needs an up-to-date search and what the
    /// passes before it in the step wrote.
    ///
    /// # Panics
    /// If `pass` is not one of [`Model::passes`].
    fn run_pass<E: Executor>(
        &self,
        exec: &E,
        pass: Pass,
        on: Particles<'_>,
        scratch: &mut Self::Scratch,
    ) -> Result<(), KernelPanic>;

    /// Times the neighbour lists were built so far, for a model that keeps them between steps
    /// (`wcsph`); `None` for one that builds them every step.
    fn list_builds(&self, scratch: &Self::Scratch) -> Option<u64> {
        let _ = scratch;
        None
    }

    /// The time step of the last step, s or the model's unit.
    fn last_dt(&self, scratch: &Self::Scratch) -> f64;

    /// The time step when the model fixes it (every step the same); `None` where it adapts to
    /// the flow, so that only the sum of the steps says the simulated time.
    fn fixed_dt(&self) -> Option<f64>;

    /// The first step's time step, from fluid at rest: the longest a step of the model takes
    /// in simulated time, for estimates of how many steps a simulated time needs.
    fn first_dt(&self) -> f64;

    /// The first particle that left what the model describes after a step, and how; `None`
    /// for a model without such a limit.
    fn first_unphysical(&self, state: &State, domain: Domain) -> Option<(usize, &'static str)> {
        let _ = (state, domain);
        None
    }
}

/// What a pass runs over: the particles, their neighbour search and the run's SIMD lanes.
#[derive(Debug)]
pub struct Particles<'a> {
    /// The particles.
    pub state: &'a mut State,
    /// The neighbour search and lists.
    pub neighbors: &'a mut AnyNeighbors,
    /// The run's SIMD path.
    pub lanes: AnyLanes,
    /// The walls.
    pub domain: Domain,
}

/// The panic of [`Model::run_pass`] for a pass the model does not have.
pub fn no_such_pass(preset: Preset, pass: Pass) -> ! {
    panic!("the {preset} preset has no {} pass", pass.as_str())
}

/// A model's scratch: arrays its passes share within a step.
pub trait Scratch: Debug + Clone + Send + Sync + 'static {
    /// Heap bytes held (capacity).
    fn heap_bytes(&self) -> usize;
}

/// Any model's scratch, held by a simulation that does not name its model.
#[derive(Debug)]
pub struct AnyScratch(Box<dyn Erased>);

impl AnyScratch {
    /// The scratch of `model` for a run of `n` particles searched by `search`
    /// ([`Model::scratch`]).
    pub fn of_model<M: Model>(model: &M, n: usize, search: &AnyNeighbors) -> Self {
        AnyScratch(Box::new(model.scratch(n, search)))
    }

    /// The scratch, as the model that made it knows it.
    ///
    /// # Panics
    /// If it is another model's (a simulation's model never changes).
    pub fn of<S: Scratch>(&self) -> &S {
        let any: &dyn Any = self.0.as_any();
        any.downcast_ref()
            .expect("a model's scratch is the one it made")
    }

    /// [`AnyScratch::of`], to write.
    pub fn of_mut<S: Scratch>(&mut self) -> &mut S {
        let any: &mut dyn Any = self.0.as_any_mut();
        any.downcast_mut()
            .expect("a model's scratch is the one it made")
    }

    /// Heap bytes held (capacity).
    pub fn heap_bytes(&self) -> usize {
        self.0.heap_bytes()
    }
}

impl Clone for AnyScratch {
    fn clone(&self) -> Self {
        AnyScratch(self.0.boxed())
    }
}

/// A [`Scratch`] behind a pointer that forgets its type.
trait Erased: Debug + Send + Sync {
    fn as_any(&self) -> &dyn Any;
    fn as_any_mut(&mut self) -> &mut dyn Any;
    fn boxed(&self) -> Box<dyn Erased>;
    fn heap_bytes(&self) -> usize;
}

impl<S: Scratch> Erased for S {
    fn as_any(&self) -> &dyn Any {
        self
    }
    fn as_any_mut(&mut self) -> &mut dyn Any {
        self
    }
    fn boxed(&self) -> Box<dyn Erased> {
        Box::new(self.clone())
    }
    fn heap_bytes(&self) -> usize {
        Scratch::heap_bytes(self)
    }
}
