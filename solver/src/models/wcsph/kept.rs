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
//! (positions among a cell block's candidates) still name the particles they named.

use sph_strategies::{Executor, KernelPanic};

use crate::sph::neighbors::list::written_zeros;
use crate::sph::state::Positions;

/// Particles per block of the displacement check.
pub const MOVED_BLOCK: usize = 512;

/// The positions the lists were built at, and whether the passes must build them again.
#[derive(Debug, Clone)]
pub struct KeptLists {
    /// x of every particle when the lists were built, m.
    x: Vec<f64>,
    /// y of every particle when the lists were built, m.
    y: Vec<f64>,
    /// Largest squared displacement per block of [`MOVED_BLOCK`] particles, m².
    block_max: Vec<f64>,
    /// Whether `x` and `y` hold positions the grid and the lists were built at.
    built: bool,
    /// Whether the grid was rebuilt and the lists are still to be built at its positions.
    relist: bool,
    /// Times the lists were built (for tests and the trace's reader).
    builds: u64,
}

impl KeptLists {
    /// Room for `n` particles; nothing built yet.
    pub fn new(n: usize) -> KeptLists {
        KeptLists {
            x: written_zeros(n),
            y: written_zeros(n),
            block_max: written_zeros(n.div_ceil(MOVED_BLOCK)),
            built: false,
            relist: true,
            builds: 0,
        }
    }

    /// Whether the lists no longer serve: nothing was built yet, or some particle of `pos` has
    /// moved from where the lists were built by a squared distance over `relist_sq`. The
    /// largest displacement is found in parallel blocks. (A position that is not a number
    /// never gets here: the step that made it stops the run, its velocity being NaN too.)
    pub fn stale<E: Executor>(
        &mut self,
        exec: &E,
        pos: Positions<'_>,
        relist_sq: f64,
    ) -> Result<bool, KernelPanic> {
        if !self.built {
            return Ok(true);
        }
        let (x, y) = (&self.x[..], &self.y[..]);
        exec.for_each_chunk(&mut self.block_max[..], |first, maxima| {
            for (k, m) in maxima.iter_mut().enumerate() {
                let lo = (first + k) * MOVED_BLOCK;
                let hi = (lo + MOVED_BLOCK).min(x.len());
                *m = largest_move_squared(
                    Positions {
                        x: &pos.x[lo..hi],
                        y: &pos.y[lo..hi],
                    },
                    Positions {
                        x: &x[lo..hi],
                        y: &y[lo..hi],
                    },
                );
            }
        })?;
        Ok(self.block_max.iter().any(|&m| m > relist_sq))
    }

    /// Records `pos` as where the grid is rebuilt and the lists will be built: the next
    /// neighbour pass builds them ([`KeptLists::take_relist`]).
    pub fn rebuilt_at<E: Executor>(
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

    /// The positions the grid and the lists were built at.
    pub fn positions(&self) -> Positions<'_> {
        Positions {
            x: &self.x,
            y: &self.y,
        }
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

/// The largest squared distance between `now` and `then`, particle by particle (0 for none).
#[inline]
fn largest_move_squared(now: Positions<'_>, then: Positions<'_>) -> f64 {
    let moves = now.x.iter().zip(now.y).zip(then.x.iter().zip(then.y));
    moves.fold(0.0, |m: f64, ((&x, &y), (&x0, &y0))| {
        let (dx, dy) = (x - x0, y - y0);
        m.max(dx * dx + dy * dy)
    })
}

#[cfg(test)]
mod tests {
    use sph_strategies::seq::SeqExecutor;

    use super::*;
    use crate::models::Physics;
    use crate::models::wcsph::params::WcParams;
    use crate::models::wcsph::scene::Fill;
    use crate::scene::Scene;
    use crate::solver::Simulation;
    use crate::sph::neighbors::NeighborMode;

    #[test]
    fn lists_are_stale_until_built_and_again_once_a_particle_moves_past_the_limit() {
        let limit = 0.25f64;
        let x = [0.0, 1.0, 2.0];
        let y = |d: f64| [0.0, 0.0, 5.0 + d];
        let stale = |kept: &mut KeptLists, d: f64| {
            let y = y(d);
            let pos = Positions { x: &x, y: &y };
            kept.stale(&SeqExecutor, pos, limit * limit).unwrap()
        };
        let mut kept = KeptLists::new(3);
        assert!(stale(&mut kept, 0.0));
        let y0 = y(0.0);
        kept.rebuilt_at(&SeqExecutor, Positions { x: &x, y: &y0 })
            .unwrap();
        assert!(kept.take_relist() && !kept.take_relist());
        assert_eq!(kept.builds(), 1);
        for d in [0.0, 0.1, -0.2, 0.249] {
            assert!(!stale(&mut kept, d), "{d}");
        }
        for d in [0.251, -0.3, 7.0] {
            assert!(stale(&mut kept, d), "{d}");
        }
    }

    fn dam(mode: NeighborMode, skin: Option<f64>) -> Simulation {
        let scene = Scene::tank(Fill::DamBreak, 8).unwrap();
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
        for mode in NeighborMode::ALL {
            let mut kept = dam(mode, None);
            let mut fresh = dam(mode, Some(0.0));
            kept.advance(&SeqExecutor, steps).unwrap();
            fresh.advance(&SeqExecutor, steps).unwrap();
            assert!(bits(&kept) == bits(&fresh), "{mode}: the states differ");
            // The dam moves from the first step: with no skin, every step builds.
            assert_eq!(fresh.list_builds(), Some(steps as u64), "{mode}");
            let built = kept.list_builds().unwrap();
            assert!(
                built >= 2 && built <= steps as u64 / 4,
                "{mode}: built {built} times"
            );
        }
    }
}
