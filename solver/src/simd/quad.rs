//! Four f64 lanes ([`F64x4`]): the force pass's arithmetic on two neighbours at once, the x and
//! y of each, on the paths whose vectors hold four lanes.
//!
//! A pair's force takes three divisions of two lanes and a square root: on this project's VMs
//! a division takes the same time on four lanes as on two (about 4 cycles, a square root about
//! 7.5), so two neighbours at once take half the divider's time (6 % off the grid's reference
//! run; four pairs in eight lanes took no more off: the divider is not all the pass waits on).
//! Every operation is lane-wise IEEE arithmetic, so each lane has the bits the
//! scalar code computes.

use std::ops::{Add, Div, Mul, Neg, Sub};
/// A path's four-lane arithmetic. The portable path computes one lane at a time: its vectors
/// hold two lanes, and its force pass takes one neighbour at a time
/// ([`TWO_NEIGHBORS`](Quad::TWO_NEIGHBORS) is false).
pub trait Quad: Copy {
    /// Four lanes in a register of this path.
    type F4: Copy;
    /// Whether the force pass takes two neighbours at a time on this path.
    const TWO_NEIGHBORS: bool;
    /// The lanes holding `lanes`.
    fn load4(self, lanes: [f64; 4]) -> Self::F4;
    /// The lanes as an array.
    fn store4(self, v: Self::F4) -> [f64; 4];
    /// Lane-wise `a + b`.
    fn add4(self, a: Self::F4, b: Self::F4) -> Self::F4;
    /// Lane-wise `a − b`.
    fn sub4(self, a: Self::F4, b: Self::F4) -> Self::F4;
    /// Lane-wise `a · b`.
    fn mul4(self, a: Self::F4, b: Self::F4) -> Self::F4;
    /// Lane-wise `a / b`.
    fn div4(self, a: Self::F4, b: Self::F4) -> Self::F4;
    /// Lane-wise `−a` (the sign flipped, as the scalar `-x`: not `0 − a`).
    fn neg4(self, a: Self::F4) -> Self::F4;
    /// Lane-wise `a` where `a > 0`, else `+0` (NaN included).
    fn positive4(self, a: Self::F4) -> Self::F4;
    /// The square roots of two values at once.
    fn sqrt2(self, a: [f64; 2]) -> [f64; 2];
}

/// Four f64 lanes of path `L`, with the arithmetic operators (lane-wise IEEE), so that code on
/// two neighbours at once reads as the scalar code on one.
#[derive(Clone, Copy)]
pub struct F64x4<L: Quad> {
    lanes: L,
    v: L::F4,
}

impl<L: Quad> F64x4<L> {
    /// The lanes holding `v`.
    #[inline(always)]
    pub fn new(lanes: L, v: [f64; 4]) -> Self {
        F64x4 {
            lanes,
            v: lanes.load4(v),
        }
    }

    /// Two pairs of lanes, `a` in the first two and `b` in the last: one value of each of two
    /// neighbours.
    #[inline(always)]
    pub fn pairs(lanes: L, [a0, a1]: [f64; 2], [b0, b1]: [f64; 2]) -> Self {
        Self::new(lanes, [a0, a1, b0, b1])
    }

    /// `a` in the first two lanes and `b` in the last two.
    #[inline(always)]
    pub fn halves_of(lanes: L, a: f64, b: f64) -> Self {
        Self::new(lanes, [a, a, b, b])
    }

    /// Each lane where above zero, else `+0`.
    #[inline(always)]
    pub fn positive(self) -> Self {
        self.with(self.lanes.positive4(self.v))
    }

    /// The first two lanes and the last two.
    #[inline(always)]
    pub fn halves(self) -> [[f64; 2]; 2] {
        let [a0, a1, b0, b1] = self.lanes.store4(self.v);
        [[a0, a1], [b0, b1]]
    }

    #[inline(always)]
    fn with(self, v: L::F4) -> Self {
        F64x4 {
            lanes: self.lanes,
            v,
        }
    }

    #[inline(always)]
    fn splat(self, x: f64) -> L::F4 {
        self.lanes.load4([x; 4])
    }
}

impl<L: Quad> Add for F64x4<L> {
    type Output = Self;
    #[inline(always)]
    fn add(self, b: Self) -> Self {
        self.with(self.lanes.add4(self.v, b.v))
    }
}

impl<L: Quad> Sub for F64x4<L> {
    type Output = Self;
    #[inline(always)]
    fn sub(self, b: Self) -> Self {
        self.with(self.lanes.sub4(self.v, b.v))
    }
}

impl<L: Quad> Mul for F64x4<L> {
    type Output = Self;
    #[inline(always)]
    fn mul(self, b: Self) -> Self {
        self.with(self.lanes.mul4(self.v, b.v))
    }
}

impl<L: Quad> Mul<f64> for F64x4<L> {
    type Output = Self;
    #[inline(always)]
    fn mul(self, b: f64) -> Self {
        self.with(self.lanes.mul4(self.v, self.splat(b)))
    }
}

/// `x · v`, operands in that order (as the scalar code writes them).
impl<L: Quad> Mul<F64x4<L>> for f64 {
    type Output = F64x4<L>;
    #[inline(always)]
    fn mul(self, v: F64x4<L>) -> F64x4<L> {
        v.with(v.lanes.mul4(v.splat(self), v.v))
    }
}

impl<L: Quad> Div for F64x4<L> {
    type Output = Self;
    #[inline(always)]
    fn div(self, b: Self) -> Self {
        self.with(self.lanes.div4(self.v, b.v))
    }
}

impl<L: Quad> Neg for F64x4<L> {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        self.with(self.lanes.neg4(self.v))
    }
}
