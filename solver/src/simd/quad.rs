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

use super::Portable;

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

impl Quad for Portable {
    type F4 = [f64; 4];
    const TWO_NEIGHBORS: bool = false;

    #[inline(always)]
    fn load4(self, lanes: [f64; 4]) -> [f64; 4] {
        lanes
    }

    #[inline(always)]
    fn store4(self, v: [f64; 4]) -> [f64; 4] {
        v
    }

    #[inline(always)]
    fn add4(self, a: [f64; 4], b: [f64; 4]) -> [f64; 4] {
        std::array::from_fn(|k| a[k] + b[k])
    }

    #[inline(always)]
    fn sub4(self, a: [f64; 4], b: [f64; 4]) -> [f64; 4] {
        std::array::from_fn(|k| a[k] - b[k])
    }

    #[inline(always)]
    fn mul4(self, a: [f64; 4], b: [f64; 4]) -> [f64; 4] {
        std::array::from_fn(|k| a[k] * b[k])
    }

    #[inline(always)]
    fn div4(self, a: [f64; 4], b: [f64; 4]) -> [f64; 4] {
        std::array::from_fn(|k| a[k] / b[k])
    }

    #[inline(always)]
    fn neg4(self, a: [f64; 4]) -> [f64; 4] {
        a.map(|x| -x)
    }

    #[inline(always)]
    fn positive4(self, a: [f64; 4]) -> [f64; 4] {
        a.map(|x| if x > 0.0 { x } else { 0.0 })
    }

    #[inline(always)]
    fn sqrt2(self, a: [f64; 2]) -> [f64; 2] {
        a.map(f64::sqrt)
    }
}

#[cfg(target_arch = "x86_64")]
mod x86 {
    use pulp::{cast, f64x4};

    use super::Quad;
    use crate::simd::{Avx2, Avx512};

    /// Both x86 paths' four lanes are AVX's (`ymm`): AVX-512's eight would hold four
    /// neighbours, and a particle has about five.
    macro_rules! quad_of {
        ($name:ident) => {
            impl Quad for $name {
                type F4 = f64x4;
                const TWO_NEIGHBORS: bool = true;

                #[inline(always)]
                fn load4(self, lanes: [f64; 4]) -> f64x4 {
                    cast(lanes)
                }

                #[inline(always)]
                fn store4(self, v: f64x4) -> [f64; 4] {
                    cast(v)
                }

                #[inline(always)]
                fn add4(self, a: f64x4, b: f64x4) -> f64x4 {
                    self.v3().add_f64x4(a, b)
                }

                #[inline(always)]
                fn sub4(self, a: f64x4, b: f64x4) -> f64x4 {
                    self.v3().sub_f64x4(a, b)
                }

                #[inline(always)]
                fn mul4(self, a: f64x4, b: f64x4) -> f64x4 {
                    self.v3().mul_f64x4(a, b)
                }

                #[inline(always)]
                fn div4(self, a: f64x4, b: f64x4) -> f64x4 {
                    self.v3().div_f64x4(a, b)
                }

                #[inline(always)]
                fn neg4(self, a: f64x4) -> f64x4 {
                    let v3 = self.v3();
                    v3.xor_f64x4(a, v3.splat_f64x4(-0.0))
                }

                #[inline(always)]
                fn positive4(self, a: f64x4) -> f64x4 {
                    // `maxpd` gives its second operand, +0, unless the first is above it
                    // (a NaN or a zero of either sign included).
                    let v3 = self.v3();
                    cast(v3.avx._mm256_max_pd(cast(a), cast(v3.splat_f64x4(0.0))))
                }

                #[inline(always)]
                fn sqrt2(self, a: [f64; 2]) -> [f64; 2] {
                    cast(self.v3().sqrt_f64x2(cast(a)))
                }
            }
        };
    }

    quad_of!(Avx2);
    quad_of!(Avx512);
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::simd::{Lanes, SimdPath};

    /// Zeros of both signs, a subnormal, the largest finite, infinities, NaN and ordinary values.
    const AWKWARD: [f64; 8] = [
        0.0,
        -0.0,
        5e-324,
        f64::MAX,
        f64::INFINITY,
        f64::NAN,
        1.0 / 3.0,
        -7.25e10,
    ];

    fn bits<L: Quad>(v: F64x4<L>) -> [u64; 4] {
        let [[a0, a1], [b0, b1]] = v.halves();
        [a0, a1, b0, b1].map(f64::to_bits)
    }

    /// Every operation of the four lanes, on every pair of awkward values.
    fn every_result<L: Lanes>(l: L) -> Vec<u64> {
        let mut out = Vec::new();
        for &x in &AWKWARD {
            for &y in &AWKWARD {
                let (a, b) = (
                    F64x4::new(l, [x, y, -x, 2.5]),
                    F64x4::new(l, [y, x, 0.1, -y]),
                );
                for v in [a + b, a - b, a * b, a / b, -a, a * y, x * b, a.positive()] {
                    out.extend(bits(v));
                }
                out.extend(l.sqrt2([x, y.abs()]).map(f64::to_bits));
            }
        }
        out
    }

    #[test]
    fn every_available_path_gives_the_scalar_bits_lane_by_lane() {
        let want = every_result(Portable);
        // The portable lanes are the scalar code: check them against it once.
        let (x, y) = (AWKWARD[6], AWKWARD[7]);
        let a = F64x4::pairs(Portable, [x, y], [1.0, 3.0]);
        let b = F64x4::halves_of(Portable, y, 3.0);
        assert_eq!(
            bits(a / b),
            [x / y, y / y, 1.0 / 3.0, 3.0 / 3.0].map(f64::to_bits)
        );
        assert_eq!(bits(-a)[0], (-x).to_bits());
        for path in SimdPath::available() {
            let got = crate::with_lanes!(path.lanes().unwrap(), l => {
                l.vectorize(#[inline(always)] || every_result(l))
            });
            assert_eq!(got.len(), want.len());
            for (k, (&g, &w)) in got.iter().zip(&want).enumerate() {
                let (g, w) = (f64::from_bits(g), f64::from_bits(w));
                // A NaN's payload may differ between paths; any NaN is a diverged run.
                let same = g.to_bits() == w.to_bits() || (g.is_nan() && w.is_nan());
                assert!(same, "{path}: result {k}: {g:e} vs {w:e}");
            }
        }
    }
}
