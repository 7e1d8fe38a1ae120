//! The sources' O(N²) loop: particle i tests every particle j.

use sph_strategies::{Executor, KernelPanic};

use super::{Neighbors, distance_squared};
use crate::simd::Lanes;
use crate::sph::state::Positions;

/// Tests every pair. Stateless.
#[derive(Debug, Clone, Copy, Default)]
pub struct AllPairs;

/// A list names a neighbour by its index.
impl Neighbors for AllPairs {
    type Key = u32;
    const KEYS_ARE_INDICES: bool = true;
    type Scratch = ();
    fn rebuild<E: Executor>(&mut self, _exec: &E, _pos: Positions<'_>) -> Result<(), KernelPanic> {
        Ok(())
    }

    #[inline(always)]
    fn for_each_within<L: Lanes>(
        &self,
        _scratch: &mut (),
        lanes: L,
        i: usize,
        pos: Positions<'_>,
        hsq: f64,
        mut visit: impl FnMut(usize, f64, u32),
    ) {
        let (xi, yi) = (pos.x[i], pos.y[i]);
        // Eight candidates at a time: their squared distances and a mask of those in reach,
        // in the lanes of the run's SIMD path; the hits are visited in index order.
        let (xs, x_tail) = pos.x.as_chunks::<8>();
        let (ys, _) = pos.y.as_chunks::<8>();
        for (b, (bx, by)) in xs.iter().zip(ys).enumerate() {
            let near = lanes.near8(xi, yi, bx, by, hsq);
            let mut mask = near.mask;
            while mask != 0 {
                let k = mask.trailing_zeros() as usize;
                mask &= mask - 1;
                let j = b * 8 + k;
                visit(j, near.r2[k], j as u32);
            }
        }
        for j in pos.x.len() - x_tail.len()..pos.x.len() {
            let r2 = distance_squared(xi, yi, pos.x[j], pos.y[j]);
            if r2 < hsq {
                visit(j, r2, j as u32);
            }
        }
    }

    #[inline(always)]
    fn for_each_listed(
        &self,
        _i: usize,
        _pos: Positions<'_>,
        list: &[u32],
        mut visit: impl FnMut(usize),
    ) {
        for &j in list {
            visit(j as usize);
        }
    }
}
