//! Each path's four-lane arithmetic ([`Quad`] for [`Portable`], [`Avx2`](super::Avx2) and [`Avx512`](super::Avx512)),
//! beside the trait ([`super::quad`]) and the paths ([`super::lanes`]) it joins: the paths'
//! [`Lanes`](super::Lanes) needs [`Quad`], so these impls sit above both.

use super::lanes::Portable;
use super::quad::Quad;

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

    use super::super::lanes::{Avx2, Avx512};
    use super::super::quad::Quad;

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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::simd::quad::F64x4;
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
