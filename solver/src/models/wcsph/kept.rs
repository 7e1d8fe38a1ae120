//! Neighbour lists kept from step to step (Verlet lists with a skin): a list holds every
//! particle within 2h + skin of its own at the step it was built, and the passes sum only those
//! now within 2h. While no particle has moved more than half the skin since then, two
//! particles now within 2h were within 2h + skin then, so the list still holds every
//! neighbour, in the order it was built in; the sums run over the same particles in the same
//! order as with a list built afresh, and give the same bits.
//!
//! The rule is checked every step over every particle (the largest displacement since the
//! build, an exact maximum, so any grouping of the particles gives it), before the search: the
//! grid is rebuilt, and the lists after it, only when the rule fails, so that a grid's keys
//! (positions among a cell block's candidates) still name the particles they named. The
//! positions of the build are the grid's own copies ([`Neighbors::rebuilt_at`]); only
//! all-pairs, which keeps none, has them copied here.

use std::ops::Range;

use sph_strategies::{Executor, KernelPanic};

use crate::sph::neighbors::list::written_zeros;
use crate::sph::neighbors::{Neighbors, Rebuilt};
use crate::sph::state::Positions;

/// Particles per block of the displacement check.
pub const MOVED_BLOCK: usize = 512;

/// Whether the lists serve, and whether the passes must build them again.
#[derive(Debug, Clone)]
pub struct KeptLists {
    /// x of every particle when the lists were built, m, where the search keeps no copy of
    /// its own (all-pairs); else empty.
    x: Vec<f64>,
    /// y of every particle when the lists were built, m, as `x`.
    y: Vec<f64>,
    /// Largest squared displacement per block of [`MOVED_BLOCK`] particles, m².
    block_max: Vec<f64>,
    /// Whether the search and the lists were built.
    built: bool,
    /// Whether the grid was rebuilt and the lists are still to be built at its positions.
    relist: bool,
    /// Times the lists were built (for tests and the trace's reader).
    builds: u64,
}

impl KeptLists {
    /// Room for `n` particles searched by `search`; nothing built yet.
    pub fn new<N: Neighbors>(n: usize, search: &N) -> KeptLists {
        let copies = if search.rebuilt_at().is_some() { 0 } else { n };
        KeptLists {
            x: written_zeros(copies),
            y: written_zeros(copies),
            block_max: written_zeros(n.div_ceil(MOVED_BLOCK)),
            built: false,
            relist: true,
            builds: 0,
        }
    }

    /// Whether the lists no longer serve: nothing was built yet, or some particle of `pos` has
    /// moved from where `search` was rebuilt (and the lists built) by a squared distance over
    /// `relist_sq`. The largest displacement is found in parallel blocks. (A position that is
    /// not a number never gets here: the step that made it stops the run, its velocity being
    /// NaN too.)
    pub fn stale<E: Executor, N: Neighbors>(
        &mut self,
        exec: &E,
        pos: Positions<'_>,
        search: &N,
        relist_sq: f64,
    ) -> Result<bool, KernelPanic> {
        if !self.built {
            return Ok(true);
        }
        let own = Positions {
            x: &self.x,
            y: &self.y,
        };
        let then = search.rebuilt_at();
        let n = pos.len();
        debug_assert!(
            then.is_some() || self.x.len() == n,
            "no copies were made, but the search keeps none"
        );
        exec.for_each_chunk(&mut self.block_max[..], |first, maxima| {
            for (k, m) in maxima.iter_mut().enumerate() {
                let lo = (first + k) * MOVED_BLOCK;
                let hi = (lo + MOVED_BLOCK).min(n);
                *m = match then {
                    Some(then) => largest_move_squared_of(pos, then, lo..hi),
                    None => largest_move_squared(pos, own, lo..hi),
                };
            }
        })?;
        Ok(self.block_max.iter().any(|&m| m > relist_sq))
    }

    /// Records that the search was rebuilt at `pos` (copying them where it keeps no copy) and
    /// that the lists will be built there: the next neighbour pass builds them
    /// ([`KeptLists::take_relist`]).
    pub fn rebuilt<E: Executor>(
        &mut self,
        exec: &E,
        pos: Positions<'_>,
    ) -> Result<(), KernelPanic> {
        exec.for_each_chunk((&mut self.x[..], &mut self.y[..]), |first, (x, y)| {
            x.copy_from_slice(&pos.x[first..first + x.len()]);
            y.copy_from_slice(&pos.y[first..first + y.len()]);
        })?;
        self.built = true;
        self.relist = true;
        Ok(())
    }

    /// Whether the lists are to be built now; the answer is given once per rebuild.
    pub fn take_relist(&mut self) -> bool {
        let relist = std::mem::take(&mut self.relist);
        self.builds += u64::from(relist);
        relist
    }

    /// Times the lists were built so far.
    pub fn builds(&self) -> u64 {
        self.builds
    }

    /// Heap bytes held (capacity).
    pub fn heap_bytes(&self) -> usize {
        8 * (self.x.capacity() + self.y.capacity() + self.block_max.capacity())
    }
}

/// The largest squared distance between `now` and `then` of the particles in `range` (0 for
/// none).
#[inline]
fn largest_move_squared(now: Positions<'_>, then: Positions<'_>, range: Range<usize>) -> f64 {
    let now = (now.x[range.clone()].iter()).zip(&now.y[range.clone()]);
    let then = (then.x[range.clone()].iter()).zip(&then.y[range]);
    now.zip(then).fold(0.0, |m, ((&x, &y), (&x0, &y0))| {
        m.max(moved_squared((x, y), (x0, y0)))
    })
}

/// [`largest_move_squared`] of the particles at the places `range` of the search's copies.
#[inline]
fn largest_move_squared_of(now: Positions<'_>, then: Rebuilt<'_>, range: Range<usize>) -> f64 {
    let at = (then.at.x[range.clone()].iter()).zip(&then.at.y[range.clone()]);
    at.zip(&then.of[range]).fold(0.0, |m, ((&x0, &y0), &j)| {
        let j = j as usize;
        m.max(moved_squared((now.x[j], now.y[j]), (x0, y0)))
    })
}

/// The squared distance from `then` to `now`.
#[inline(always)]
fn moved_squared((x, y): (f64, f64), (x0, y0): (f64, f64)) -> f64 {
    let (dx, dy) = (x - x0, y - y0);
    dx * dx + dy * dy
}

#[cfg(test)]
mod tests {
    use sph_strategies::seq::SeqExecutor;

    use super::*;
    use crate::cutting::Cutting;
    use crate::models::Physics;
    use crate::models::wcsph::params::WcParams;
    use crate::models::wcsph::scene::Fill;
    use crate::scene::Scene;
    use crate::solver::Simulation;
    use crate::sph::neighbors::NeighborMode;
    use crate::sph::neighbors::{AllPairs, Bounds, Grid};

    /// Staleness as `kept` sees it, beside `search` rebuilt as the model rebuilds it.
    fn check_staleness<N: Neighbors>(mut search: N) {
        let limit = 0.25f64;
        // The moving particle first: the grid's order puts it last (its cell is a row up).
        let x = [2.0, 1.0, 0.0];
        let y = |d: f64| [5.0 + d, 0.0, 0.0];
        let mut kept = KeptLists::new(3, &search);
        let stale = |kept: &mut KeptLists, search: &N, d: f64| {
            let y = y(d);
            let pos = Positions { x: &x, y: &y };
            kept.stale(&SeqExecutor, pos, search, limit * limit)
                .unwrap()
        };
        assert!(stale(&mut kept, &search, 0.0));
        let y0 = y(0.0);
        let at = Positions { x: &x, y: &y0 };
        search.rebuild(&SeqExecutor, at).unwrap();
        kept.rebuilt(&SeqExecutor, at).unwrap();
        assert!(kept.take_relist() && !kept.take_relist());
        assert_eq!(kept.builds(), 1);
        for d in [0.0, 0.1, -0.2, 0.249] {
            assert!(!stale(&mut kept, &search, d), "{d}");
        }
        for d in [0.251, -0.3, 7.0] {
            assert!(stale(&mut kept, &search, d), "{d}");
        }
    }

    #[test]
    fn lists_are_stale_until_built_and_again_once_a_particle_moves_past_the_limit() {
        // All-pairs keeps no positions: they are copied here.
        check_staleness(AllPairs);
        assert_eq!(KeptLists::new(3, &AllPairs).heap_bytes(), 8 * (2 * 3 + 1));
        // The grid's own copies serve, in its cell order.
        let bounds = Bounds {
            min_x: -1.0,
            min_y: -1.0,
            max_x: 3.0,
            max_y: 9.0,
        };
        let grid = Grid::<u32>::new(bounds, 0.5, 3);
        assert_eq!(KeptLists::new(3, &grid).heap_bytes(), 8);
        check_staleness(grid);
    }

    fn dam(mode: NeighborMode, skin: Option<f64>) -> Simulation {
        dam_at(8, mode, skin)
    }

    fn dam_at(resolution: usize, mode: NeighborMode, skin: Option<f64>) -> Simulation {
        let scene = Scene::tank(Fill::DamBreak, resolution).unwrap();
        let Physics::Wcsph(prm) = scene.physics else {
            unreachable!("a tank is wcsph")
        };
        let prm: WcParams = skin.map_or(prm, |s| prm.with_skin(s));
        Simulation::new(prm, scene.domain, scene.state, mode)
    }

    fn bits(sim: &Simulation) -> Vec<u64> {
        let s = &sim.state;
        [&s.x, &s.y, &s.vx, &s.vy, &s.rho, &s.p]
            .iter()
            .flat_map(|v| v.iter().map(|x| x.to_bits()))
            .collect()
    }

    #[test]
    fn every_list_fits_its_slots_through_a_dam_break() {
        for mode in NeighborMode::ALL {
            let mut sim = dam(mode, None);
            for step in 0..600 {
                sim.advance(&SeqExecutor, 1).unwrap();
                assert_eq!(sim.unlisted(), 0, "{mode}, step {step}");
            }
        }
    }

    #[test]
    fn kept_lists_give_the_bits_of_lists_built_every_step_and_are_built_less_often() {
        let steps = 400;
        // R = 20 has 1418 particles: three blocks of the displacement check, the last one
        // short, each over places of the grid's order that name particles of other blocks.
        for (resolution, chunks) in [(8, 1), (20, 3)] {
            for mode in NeighborMode::ALL {
                let case = format!("{mode}, R = {resolution}");
                let mut kept = dam_at(resolution, mode, None);
                let mut fresh = dam_at(resolution, mode, Some(0.0));
                kept.advance(&Cutting(chunks), steps).unwrap();
                fresh.advance(&SeqExecutor, steps).unwrap();
                assert!(bits(&kept) == bits(&fresh), "{case}: the states differ");
                // The dam moves from the first step: with no skin, every step builds.
                assert_eq!(fresh.list_builds(), Some(steps as u64), "{case}");
                let built = kept.list_builds().unwrap();
                assert!(
                    built >= 2 && built <= steps as u64 / 4,
                    "{case}: built {built} times"
                );
            }
        }
    }
}
