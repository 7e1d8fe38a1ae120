//! The momentum and continuity sums of eight consecutive fluid particles at once, one particle
//! a lane ([`super::pairs`]): step m takes each particle's m-th listed neighbour, and each
//! lane adds its term to its own particle's sum, so every particle sums its neighbours in its
//! list's order, as one particle alone does ([`super::passes::acceleration`]), and gets its
//! bits. A lane whose list is shorter adds +0 at the steps past its end.
//!
//! The continuity pass takes two steps at once, m in lanes 0..8 and m + 1 in lanes 8..16, and
//! adds them in that order: two independent chains of loads, square root and division for
//! the processor to overlap (275 ms against 430 ms per 1500 steps at R = 40 in eight lanes).
//! The momentum pass, with more to hold per lane, measured slower so (430–440 ms against
//! 330 ms) and takes one step at a time.
//!
//! It needs lists whose keys are the neighbours' indices (all-pairs', and the grid's index
//! keys, which `wcsph` always uses) and all eight lists usable; otherwise the eight particles
//! are summed one by one.

use glam::DVec2;

use super::pairs::{self, ContinuityInputs, ContinuitySide, F8, MomentumSide};
use super::params::WcParams;
use super::passes::Listed;
use crate::sph::neighbors::{ListKey, Neighbors};
use crate::sph::state::Fields;

/// The accelerations of fluid particles `a0..a0 + 8`, or `None` where they cannot be summed
/// eight at once.
#[inline(always)]
pub fn accelerations<N: Neighbors>(
    a0: usize,
    f: &Fields<'_>,
    listed: &Listed<'_, N>,
    prm: &WcParams,
) -> Option<[DVec2; 8]> {
    let lists = Eight::of(a0, listed)?;
    let me = MomentumSide::eight(a0, f);
    let (mut sx, mut sy) = ([0.0; 8], [0.0; 8]);
    for m in 0..lists.most {
        let (b, keep) = lists.column(m);
        let (tx, ty) = pairs::momentum(&me, &b, keep, f, prm);
        for k in 0..8 {
            sx[k] += tx[k];
            sy[k] += ty[k];
        }
    }
    let mut a = [DVec2::ZERO; 8];
    for k in 0..8 {
        a[k] = pairs::acceleration(sx[k], sy[k], prm);
    }
    Some(a)
}

/// The continuity sums (dρ/dt over m) of fluid particles `a0..a0 + 8`, or `None` where they
/// cannot be summed eight at once.
#[inline(always)]
pub fn density_sums<N: Neighbors>(
    a0: usize,
    input: &ContinuityInputs<'_>,
    listed: &Listed<'_, N>,
    prm: &WcParams,
) -> Option<F8> {
    let lists = Eight::of(a0, listed)?;
    let me = ContinuitySide::eight_twice(a0, input);
    let mut sum = [0.0; 8];
    for m in (0..lists.most).step_by(2) {
        let (b, keep) = lists.columns(m);
        let term = pairs::continuity(&me, &b, keep, input, prm);
        for k in 0..16 {
            sum[k % 8] += term[k];
        }
    }
    Some(sum)
}

/// The sums of [`super::passes::wall_state`] (numerator, denominator) of wall particles
/// `w0..w0 + 8`, or `None` where they cannot be summed eight at once. `f` holds the fluid's ρ
/// and p only.
#[inline(always)]
pub fn wall_sums<N: Neighbors>(
    w0: usize,
    f: &Fields<'_>,
    listed: &Listed<'_, N>,
    prm: &WcParams,
) -> Option<(F8, F8)> {
    let lists = Eight::of(w0, listed)?;
    let xw: F8 = f.pos.x[w0..w0 + 8].try_into().expect("eight walls");
    let yw: F8 = f.pos.y[w0..w0 + 8].try_into().expect("eight walls");
    let (mut num, mut den) = ([0.0; 8], [0.0; 8]);
    for m in 0..lists.most {
        let (b, keep) = lists.column(m);
        let (tn, td) = pairs::wall((&xw, &yw), &b, keep, f, prm);
        for k in 0..8 {
            num[k] += tn[k];
            den[k] += td[k];
        }
    }
    Some((num, den))
}

/// The lists of eight consecutive particles, read by slot.
struct Eight<'a, K> {
    /// Their slots, one list after another.
    slots: &'a [K],
    /// Slots per list.
    width: usize,
    /// Each list's length.
    len: [usize; 8],
    /// The longest length.
    most: usize,
}

impl<'a, K: ListKey> Eight<'a, K> {
    /// The lists of `a0..a0 + 8`, when their keys are indices and all eight are usable.
    #[inline(always)]
    fn of<N: Neighbors<Key = K>>(a0: usize, listed: &Listed<'a, N>) -> Option<Self> {
        if !N::KEYS_ARE_INDICES {
            return None;
        }
        let lists = listed.lists;
        let width = lists.width();
        let mut len = [0; 8];
        for (k, len) in len.iter_mut().enumerate() {
            *len = lists.count[a0 + k] as usize;
        }
        // A count of `width` or more: the list did not fit.
        if len.iter().any(|&l| l >= width) {
            return None;
        }
        Some(Eight {
            slots: &lists.slots[a0 * width..(a0 + 8) * width],
            width,
            len,
            most: len.into_iter().max().unwrap_or(0),
        })
    }

    /// Each lane's m-th neighbour, and whether it has one (past its list's end a lane holds
    /// whatever its slot holds: some particle's index, as every slot ever written does).
    #[inline(always)]
    fn column(&self, m: usize) -> ([usize; 8], [bool; 8]) {
        let mut b = [0; 8];
        let mut keep = [false; 8];
        for k in 0..8 {
            b[k] = self.slots[k * self.width + m].get() as usize;
            keep[k] = m < self.len[k];
        }
        (b, keep)
    }

    /// Each list's m-th neighbour in lanes 0..8 and its (m + 1)-th in lanes 8..16, and whether
    /// it has one (past its list's end a lane holds whatever its slot holds: some particle's
    /// index, as every slot ever written does; m + 1 is a slot, since a list is shorter than
    /// its slots).
    #[inline(always)]
    fn columns(&self, m: usize) -> ([usize; 16], [bool; 16]) {
        let mut b = [0; 16];
        let mut keep = [false; 16];
        for k in 0..16 {
            let (list, slot) = (k % 8, m + k / 8);
            b[k] = self.slots[list * self.width + slot].get() as usize;
            keep[k] = slot < self.len[list];
        }
        (b, keep)
    }
}
