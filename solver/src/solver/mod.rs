//! One step = the model's passes over the particles, each handed to a strategy's executor,
//! plus the grid rebuild before them and the divergence check after them: three passes for
//! Müller's model (density, forces, integrate), six for WCSPH (max speed, neighbours, walls,
//! momentum, continuity, integrate). How each pass is cut into kernel calls lives in `schedule`, one
//! file per model; the one step loop ([`Simulation::advance_with`]) and the [`StepHooks`]
//! through which a caller wraps each phase's executor (tracing, fault injection) or the
//! check, in `step`.

mod schedule;
mod step;

pub use schedule::wcsph::SPEED_BLOCK;
pub use step::{Phase, PhaseJob, StepHooks};

use sph_strategies::{Executor, KernelPanic};

use crate::simd::{self, AnyLanes, SimdPath};
use crate::sph::neighbors::{
    self, AnyNeighbors, CellOrderNeedsGrid, GridKeys, NeighborMode, Neighbors, SLOTS, Searched,
    SumOrder, WCSPH_SLOTS,
};
use crate::sph::physics::Physics;
use crate::sph::state::{Domain, Positions, State};
use crate::with_lanes;

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
    wcsph: schedule::wcsph::Scratch,
}

/// One pass of a step, for benchmarks and traces.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Pass {
    /// Müller: density and pressure (and each particle's neighbour list).
    Density,
    /// Müller: pressure, viscosity and gravity forces.
    Forces,
    /// Both: each particle's own update (Müller: symplectic Euler and the walls; WCSPH: kick,
    /// density, drift).
    Integrate,
    /// WCSPH: the largest fluid speed, a reduction, and from it the time step.
    MaxSpeed,
    /// WCSPH: every particle's neighbour list.
    Neighbors,
    /// WCSPH: the walls' pressure and density from the fluid.
    Walls,
    /// WCSPH: each fluid particle's acceleration (and its neighbour list).
    Momentum,
    /// WCSPH: each fluid particle's density rate.
    Continuity,
}

impl Pass {
    /// Müller's three passes in step order.
    pub const MUELLER: [Pass; 3] = [Pass::Density, Pass::Forces, Pass::Integrate];

    /// The WCSPH step's six passes in step order.
    pub const WCSPH: [Pass; 6] = [
        Pass::MaxSpeed,
        Pass::Neighbors,
        Pass::Walls,
        Pass::Momentum,
        Pass::Continuity,
        Pass::Integrate,
    ];

    /// Every pass: Müller's, then those only WCSPH has.
    pub const ALL: [Pass; 8] = [
        Pass::Density,
        Pass::Forces,
        Pass::Integrate,
        Pass::MaxSpeed,
        Pass::Neighbors,
        Pass::Walls,
        Pass::Momentum,
        Pass::Continuity,
    ];

    /// Lower-case name, as in bench ids and traces.
    pub fn as_str(self) -> &'static str {
        match self {
            Pass::Density => "density",
            Pass::Forces => "forces",
            Pass::Integrate => "integrate",
            Pass::MaxSpeed => "max speed",
            Pass::Neighbors => "neighbours",
            Pass::Walls => "walls",
            Pass::Momentum => "momentum",
            Pass::Continuity => "continuity",
        }
    }
}

/// Runs `$body` with `$nb` bound to the concrete search inside `$any` (a `&mut AnyNeighbors`)
/// and `$lists` to its lists, so that the code in `$body` is monomorphised per search (picked
/// once per call, not per particle).
macro_rules! with_search {
    ($any:expr, ($nb:ident, $lists:ident) => $body:expr) => {
        match $any {
            AnyNeighbors::AllPairs(Searched {
                search: $nb,
                lists: $lists,
            }) => $body,
            AnyNeighbors::GridByPosition(Searched {
                search: $nb,
                lists: $lists,
            }) => $body,
            AnyNeighbors::GridByIndex(Searched {
                search: $nb,
                lists: $lists,
            }) => $body,
            AnyNeighbors::GridInCellOrder(Searched {
                search: $nb,
                lists: $lists,
            }) => $body,
            AnyNeighbors::GridByIndexInCellOrder(Searched {
                search: $nb,
                lists: $lists,
            }) => $body,
        }
    };
}

/// [`with_search!`], and `$l` bound to the lanes the search tests candidates in: the run's
/// SIMD path for all-pairs; for the grid AVX-512's, which packs a row's hits eight candidates
/// at a time (where the grid's `scans_packed` says so), and otherwise the portable lanes: the
/// grid tests its few candidates per row one by one there, compiled for the target. Müller's
/// force pass, which searches only for a pile, gets the run's path on every search.
macro_rules! with_search_lanes {
    ($any:expr, $lanes:expr, ($nb:ident, $lists:ident, $l:ident) => $body:expr) => {
        match $any {
            AnyNeighbors::AllPairs(Searched { search: $nb, lists: $lists }) => {
                with_lanes!($lanes, $l => $body)
            }
            // Every grid (`with_search!`'s all-pairs arm is never taken here).
            #[cfg(target_arch = "x86_64")]
            grid if matches!($lanes, simd::AnyLanes::Avx512(_)) => {
                let simd::AnyLanes::Avx512($l) = $lanes else { unreachable!() };
                with_search!(grid, ($nb, $lists) => $body)
            }
            grid => {
                let $l = simd::Portable;
                with_search!(grid, ($nb, $lists) => $body)
            }
        }
    };
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
        let (fluid, state_len) = (physics.fluid(state.len()), state.len());
        let bounds = physics.search_bounds(domain);
        let lists = match physics {
            Physics::Mueller(_) => (fluid, SLOTS),
            Physics::Wcsph(_) => (state_len, WCSPH_SLOTS),
        };
        let radius = physics.search_radius();
        let neighbors = neighbors::build(mode, bounds, radius, state_len, lists);
        let wcsph = match physics {
            Physics::Mueller(_) => schedule::wcsph::Scratch::new(0),
            Physics::Wcsph(_) => schedule::wcsph::Scratch::new(fluid),
        };
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
            wcsph,
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
        self
    }

    /// The same simulation with its sums over neighbours in `order` ([`SumOrder`]): cell order
    /// is faster on the grid but does not give the sources' bits.
    ///
    /// # Errors
    /// Cell order with all-pairs, which has no cells.
    pub fn with_sum_order(mut self, order: SumOrder) -> Result<Self, CellOrderNeedsGrid> {
        self.neighbors = self.neighbors.with_sum_order(order)?;
        Ok(self)
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
        self
    }

    /// How the grid's neighbour lists name neighbours; `None` for all-pairs.
    pub fn grid_keys(&self) -> Option<GridKeys> {
        self.neighbors.grid_keys()
    }

    /// The SIMD path the run's vector code runs on, so that `--json` and `meta.json` name
    /// what ran: the chosen one for all-pairs' neighbour tests, for Müller's force pass (two
    /// neighbours at once) and for the grid's packed scan (AVX-512); `portable` for a `wcsph`
    /// run on the grid on another path, which uses none of them (the grid then tests its few
    /// candidates per row one by one).
    pub fn simd(&self) -> SimdPath {
        match (&self.neighbors, &self.physics, self.lanes.path()) {
            (AnyNeighbors::AllPairs(_), _, path)
            | (_, Physics::Mueller(_), path)
            | (_, _, path @ SimdPath::Avx512) => path,
            _ => SimdPath::Portable,
        }
    }

    /// The model's passes, in step order.
    pub fn passes(&self) -> &'static [Pass] {
        Self::passes_of(&self.physics)
    }

    /// The passes of `physics`' model, in step order.
    pub fn passes_of(physics: &Physics) -> &'static [Pass] {
        match physics {
            Physics::Mueller(_) => &Pass::MUELLER,
            Physics::Wcsph(_) => &Pass::WCSPH,
        }
    }

    /// Particles that move: the first `fluid()` of the state (the rest are walls).
    pub fn fluid(&self) -> usize {
        self.physics.fluid(self.state.len())
    }

    /// The time step of the last step (WCSPH's adapts to the flow), s.
    pub fn last_dt(&self) -> f64 {
        match self.physics {
            Physics::Mueller(p) => p.dt,
            Physics::Wcsph(_) => self.wcsph.dt,
        }
    }

    /// Brings the neighbour search up to date with the current positions, on `exec`.
    pub fn rebuild_neighbors_on<E: Executor>(&mut self, exec: &E) -> Result<(), KernelPanic> {
        let pos = Positions {
            x: &self.state.x,
            y: &self.state.y,
        };
        with_search!(&mut self.neighbors, (nb, _lists) => nb.rebuild(exec, pos))
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
        use schedule::{mueller, wcsph};
        let (s, nb, lanes) = (&mut self.state, &mut self.neighbors, self.lanes);
        match (&self.physics, pass) {
            (Physics::Mueller(prm), Pass::Density) => {
                with_search_lanes!(nb, lanes, (nb, lists, l) => mueller::density(exec, l, &*nb, lists, s, prm))
            }
            (Physics::Mueller(prm), Pass::Forces) => {
                with_search!(nb, (nb, lists) => with_lanes!(lanes, l => mueller::forces(exec, l, &*nb, lists, s, prm)))
            }
            (Physics::Mueller(prm), Pass::Integrate) => {
                with_lanes!(lanes, l => mueller::integrate(exec, l, s, prm, self.domain))
            }
            (Physics::Wcsph(prm), Pass::MaxSpeed) => {
                wcsph::max_speed(exec, s, &mut self.wcsph, prm)
            }
            (Physics::Wcsph(prm), Pass::Neighbors) => {
                with_search_lanes!(nb, lanes, (nb, lists, l) => wcsph::neighbors(exec, l, &*nb, lists, s, prm))
            }
            (Physics::Wcsph(prm), Pass::Walls) => {
                with_search!(nb, (nb, lists) => wcsph::walls(exec, &*nb, lists, s, prm))
            }
            (Physics::Wcsph(prm), Pass::Momentum) => {
                with_search!(nb, (nb, lists) => wcsph::momentum(exec, &*nb, lists, s, prm))
            }
            (Physics::Wcsph(prm), Pass::Continuity) => {
                with_search!(nb, (nb, lists) => wcsph::continuity(exec, &*nb, lists, s, &mut self.wcsph, prm))
            }
            (Physics::Wcsph(prm), Pass::Integrate) => wcsph::integrate(exec, s, &self.wcsph, prm),
            (physics, pass) => panic!(
                "the {} preset has no {} pass",
                physics.preset(),
                pass.as_str()
            ),
        }
    }

    /// Bytes held by the neighbour search, lists and the model's scratch arrays, for memory
    /// reports.
    pub fn neighbor_heap_bytes(&self) -> usize {
        self.neighbors.heap_bytes() + self.wcsph.heap_bytes()
    }
}
