//! The sources' O(N²) loop: particle i tests every particle j.

use sph_strategies::{Executor, KernelPanic};

use super::{Neighbors, distance_squared};
use crate::sph::state::Positions;

/// Tests every pair. Stateless.
#[derive(Debug, Clone, Copy, Default)]
pub struct AllPairs;

/// Candidates tested per block; the test is branch-free within a block so it vectorises.
const BLOCK: usize = 8;

impl Neighbors for AllPairs {
    fn rebuild<E: Executor>(&mut self, _exec: &E, _pos: Positions<'_>) -> Result<(), KernelPanic> {
        Ok(())
    }

    #[inline]
    fn for_each_within(
        &self,
        i: usize,
        pos: Positions<'_>,
        hsq: f64,
        mut visit: impl FnMut(usize, f64),
    ) {
        let (xi, yi) = (pos.x[i], pos.y[i]);
        let blocks = pos.x.chunks_exact(BLOCK).zip(pos.y.chunks_exact(BLOCK));
        let tail_start = pos.x.len() - pos.x.len() % BLOCK;
        for (b, (bx, by)) in blocks.enumerate() {
            // Most pairs are far apart. A pair can only be within reach if dx*dx < HSQ
            // (adding dy*dy and rounding never makes r2 smaller), a test that vectorises
            // without branches; only blocks that pass it get the exact test, in index order.
            let near = bx
                .iter()
                .fold(false, |near, &xj| near | ((xj - xi) * (xj - xi) < hsq));
            if !near {
                continue;
            }
            for k in 0..BLOCK {
                let r2 = distance_squared(xi, yi, bx[k], by[k]);
                if r2 < hsq {
                    visit(b * BLOCK + k, r2);
                }
            }
        }
        for j in tail_start..pos.x.len() {
            let r2 = distance_squared(xi, yi, pos.x[j], pos.y[j]);
            if r2 < hsq {
                visit(j, r2);
            }
        }
    }
}
