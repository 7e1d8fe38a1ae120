//! The lanes of each path: one operation, the squared distances from particle i to eight
//! candidates and which of them are below the search radius squared.

use super::quad::Quad;

/// The squared distances to eight candidates and the bit mask of those below `hsq` (bit k set
/// when candidate k is within reach).
///
/// Aligned to 64 bytes, `r2` first, like the lane arrays of [`Hits8`] and the neighbour
/// search's `Eight`: a search stores the eight lanes with one vector store into a temporary on
/// the stack and reads the hits back one by one. Only 16-byte aligned, that store straddled a
/// cache line three times in four, and a 4 KiB page wherever the temporary happened to sit
/// less than 64 bytes below a page boundary; there the all-pairs density pass took 3–4× as
/// long on AVX2 and AVX-512 (`seq` now and then, as address-space randomisation placed the
/// main thread's stack; `crossbeam-pool` on 1 core in every run, its session thread's fresh
/// stack putting the temporary at the same place each time).
#[derive(Debug, Clone, Copy)]
#[repr(C, align(64))]
pub struct Near8 {
    /// `dx*dx + dy*dy` per candidate, `d = x_j − x_i`, exactly as the scalar code computes it.
    pub r2: [f64; 8],
    /// Bit k: `r2[k] < hsq`.
    pub mask: u8,
}

/// Eight candidates of a grid's row, for [`Lanes::hits8`].
#[derive(Debug, Clone, Copy)]
pub struct Row8<'a> {
    /// Their x.
    pub xs: &'a [f64; 8],
    /// Their y.
    pub ys: &'a [f64; 8],
    /// Their indices.
    pub order: &'a [u32; 8],
    /// The position of the first among the particle's candidates (the others follow).
    pub first: u32,
}

/// Eight candidates' hits ([`Lanes::hits8`]), each lane array on a 64-byte boundary (see
/// [`Near8`]).
#[derive(Debug, Clone, Copy)]
#[repr(C, align(64))]
pub struct Hits8 {
    /// Every candidate's squared distance, as [`Near8::r2`].
    pub r2: [f64; 8],
    /// The hits `(j << 32) | position` in candidate order, in the first `count` places.
    pub hits: [u64; 8],
    /// The hits' squared distances, in the first `count` places.
    pub hit_r2: [f64; 8],
    /// The number of hits.
    pub count: usize,
}

/// One path's instructions.
pub trait Lanes: Copy + Send + Sync + Quad {
    /// Runs `f` compiled with this path's instructions enabled: code inlined into `f` (mark
    /// the closure `#[inline(always)]`) may use them, including the compiler's own
    /// vectorisation.
    fn vectorize<R>(self, f: impl FnOnce() -> R) -> R;

    /// The squared distances from `(xi, yi)` to eight candidates and which are below `hsq`.
    fn near8(self, xi: f64, yi: f64, xs: &[f64; 8], ys: &[f64; 8], hsq: f64) -> Near8;

    /// [`Lanes::near8`] of the candidates whose bit is set in `lanes` alone: the other lanes'
    /// squared distances are `+∞` and their bits clear.
    #[inline(always)]
    fn near8_of(self, me: (f64, f64), xs: &[f64; 8], ys: &[f64; 8], hsq: f64, lanes: u8) -> Near8 {
        let mut near = self.near8(me.0, me.1, xs, ys, hsq);
        for (k, r2) in near.r2.iter_mut().enumerate() {
            *r2 = if lanes & (1 << k) != 0 {
                *r2
            } else {
                f64::INFINITY
            };
        }
        near.mask &= lanes;
        near
    }

    /// Bit k set where `v[k] != x`.
    #[inline(always)]
    fn ne8(self, v: [u32; 8], x: u32) -> u8 {
        (0..8).fold(0, |m, k| m | (u8::from(v[k] != x) << k))
    }

    /// Bit k set where `v[k] < x`.
    #[inline(always)]
    fn below16(self, v: [u32; 16], x: u32) -> u16 {
        (0..16).fold(0, |m, k| m | (u16::from(v[k] < x) << k))
    }

    /// The values of `v` whose bit is set in `mask`, packed at the front in lane order (the
    /// other places zero).
    #[inline(always)]
    fn compress8(self, v: [u32; 8], mask: u8) -> [u32; 8] {
        let mut packed = [0; 8];
        let mut len = 0;
        for (k, &x) in v.iter().enumerate() {
            packed[len % 8] = x;
            len += usize::from(mask & (1 << k) != 0);
        }
        // Places past the packed values hold leftovers: cleared.
        for (k, p) in packed.iter_mut().enumerate() {
            *p = if k < len { *p } else { 0 };
        }
        packed
    }

    /// Whether [`Lanes::hits8`] packs the hits in registers (AVX-512's compress), so that a
    /// grid scans its candidates eight at a time (a grid of up to 4096 particles, or a larger
    /// grid's blocks of 16 candidates or more: the grid's `scans_packed`); without it the grid
    /// tests them one by one.
    const PACKS_HITS: bool = false;

    /// Of the eight candidates of `row`, those whose bit is set in `lanes` tested against
    /// `hsq` from `(xi, yi)`: every squared distance (as [`Lanes::near8`]), and the hits (those
    /// below) packed at the front in candidate order, a hit `(j << 32) | position`.
    #[inline(always)]
    fn hits8(self, (xi, yi): (f64, f64), row: Row8<'_>, lanes: u8, hsq: f64) -> Hits8 {
        let near = self.near8(xi, yi, row.xs, row.ys, hsq);
        let mut found = Hits8 {
            r2: near.r2,
            hits: [0; 8],
            hit_r2: [0.0; 8],
            count: 0,
        };
        for (k, &j) in row.order.iter().enumerate() {
            if near.mask & lanes & (1 << k) != 0 {
                found.hits[found.count] =
                    (u64::from(j) << 32) | u64::from(row.first.wrapping_add(k as u32));
                found.hit_r2[found.count] = near.r2[k];
                found.count += 1;
            }
        }
        found
    }
}

/// The compiled target's own instructions: a plain loop the compiler vectorises as it can.
#[derive(Debug, Clone, Copy, Default)]
pub struct Portable;

impl Lanes for Portable {
    #[inline(always)]
    fn vectorize<R>(self, f: impl FnOnce() -> R) -> R {
        f()
    }

    #[inline(always)]
    fn near8(self, xi: f64, yi: f64, xs: &[f64; 8], ys: &[f64; 8], hsq: f64) -> Near8 {
        let mut r2 = [0.0; 8];
        let mut mask = 0u8;
        for k in 0..8 {
            let (dx, dy) = (xs[k] - xi, ys[k] - yi);
            r2[k] = dx * dx + dy * dy;
            mask |= u8::from(r2[k] < hsq) << k;
        }
        Near8 { mask, r2 }
    }
}

#[cfg(target_arch = "x86_64")]
pub use x86::{Avx2, Avx512};

#[cfg(target_arch = "x86_64")]
mod x86 {
    use pulp::x86::{V3, V4};
    use pulp::{cast, f64x4, f64x8, u32x8, u64x8};

    use super::{Hits8, Lanes, Near8, Row8};

    /// A path's lanes type around its `pulp` token: detection, `vectorize`, and `near8` as
    /// one call with the features on (inside a vectorised pass it inlines to nothing; called
    /// from elsewhere it is one call, not a call per instruction).
    macro_rules! lanes_of {
        ($(#[$doc:meta])* $name:ident($token:ident), $detect_doc:literal, $($packs:tt)*) => {
            $(#[$doc])*
            #[derive(Debug, Clone, Copy)]
            pub struct $name($token);

            impl $name {
                #[doc = $detect_doc]
                pub fn detect() -> Option<$name> {
                    $token::try_new().map($name)
                }
            }

            impl Lanes for $name {
                #[inline(always)]
                fn vectorize<R>(self, f: impl FnOnce() -> R) -> R {
                    self.0.vectorize(f)
                }

                #[inline(always)]
                fn near8(self, xi: f64, yi: f64, xs: &[f64; 8], ys: &[f64; 8], hsq: f64) -> Near8 {
                    self.vectorize(
                        #[inline(always)]
                        || self.near8_inline(xi, yi, xs, ys, hsq),
                    )
                }

                $($packs)*
            }
        };
    }

    lanes_of!(
        /// AVX2: two 4-lane halves, each compare turned into four mask bits.
        Avx2(V3),
        "The lanes, if this CPU has AVX2 (and the rest of x86-64-v3).",
    );

    lanes_of!(
        /// AVX-512: one 8-lane compare straight into a mask register.
        Avx512(V4),
        "The lanes, if this CPU has AVX-512 F/BW/CD/DQ/VL (x86-64-v4).",
        const PACKS_HITS: bool = true;

        #[inline(always)]
        fn near8_of(
            self,
            me: (f64, f64),
            xs: &[f64; 8],
            ys: &[f64; 8],
            hsq: f64,
            lanes: u8,
        ) -> Near8 {
            self.vectorize(
                #[inline(always)]
                || {
                    let near = self.near8_inline(me.0, me.1, xs, ys, hsq);
                    let v = self.0;
                    let r2 = v.avx512f._mm512_mask_blend_pd(
                        lanes,
                        cast(v.splat_f64x8(f64::INFINITY)),
                        cast(near.r2),
                    );
                    Near8 {
                        mask: near.mask & lanes,
                        r2: cast(r2),
                    }
                },
            )
        }

        #[inline(always)]
        fn ne8(self, v: [u32; 8], x: u32) -> u8 {
            self.vectorize(
                #[inline(always)]
                || {
                    let v4 = self.0;
                    v4.avx512f._mm256_cmpneq_epu32_mask(cast(v), cast(v4.splat_u32x8(x)))
                },
            )
        }

        #[inline(always)]
        fn below16(self, v: [u32; 16], x: u32) -> u16 {
            self.vectorize(
                #[inline(always)]
                || {
                    let v4 = self.0;
                    v4.avx512f._mm512_cmplt_epu32_mask(cast(v), cast(v4.splat_u32x16(x)))
                },
            )
        }

        #[inline(always)]
        fn compress8(self, v: [u32; 8], mask: u8) -> [u32; 8] {
            self.vectorize(
                #[inline(always)]
                || cast(self.0.avx512f._mm256_maskz_compress_epi32(mask, cast(v))),
            )
        }

        #[inline(always)]
        fn hits8(self, me: (f64, f64), row: Row8<'_>, lanes: u8, hsq: f64) -> Hits8 {
            self.vectorize(
                #[inline(always)]
                || self.hits8_inline(me, row, lanes, hsq),
            )
        }
    );

    impl Avx2 {
        /// The AVX2 (x86-64-v3) token.
        #[inline(always)]
        pub(in crate::simd) fn v3(self) -> V3 {
            self.0
        }

        #[inline(always)]
        fn near8_inline(self, xi: f64, yi: f64, xs: &[f64; 8], ys: &[f64; 8], hsq: f64) -> Near8 {
            let v = self.0;
            let half = |xs: [f64; 4], ys: [f64; 4]| {
                let dx = v.sub_f64x4(cast(xs), v.splat_f64x4(xi));
                let dy = v.sub_f64x4(cast(ys), v.splat_f64x4(yi));
                let r2 = v.add_f64x4(v.mul_f64x4(dx, dx), v.mul_f64x4(dy, dy));
                let below = v.cmp_lt_f64x4(r2, v.splat_f64x4(hsq));
                let bits = v.avx._mm256_movemask_pd(cast(below)) as u8;
                (bits, cast::<f64x4, [f64; 4]>(r2))
            };
            let split = |a: &[f64; 8]| -> ([f64; 4], [f64; 4]) {
                ([a[0], a[1], a[2], a[3]], [a[4], a[5], a[6], a[7]])
            };
            let ((xlo, xhi), (ylo, yhi)) = (split(xs), split(ys));
            let (mlo, rlo) = half(xlo, ylo);
            let (mhi, rhi) = half(xhi, yhi);
            let mut r2 = [0.0; 8];
            r2[..4].copy_from_slice(&rlo);
            r2[4..].copy_from_slice(&rhi);
            Near8 {
                mask: mlo | (mhi << 4),
                r2,
            }
        }
    }

    impl Avx512 {
        /// The AVX2 (x86-64-v3) token, which AVX-512's implies.
        #[inline(always)]
        pub(in crate::simd) fn v3(self) -> V3 {
            *self.0
        }

        #[inline(always)]
        fn near8_inline(self, xi: f64, yi: f64, xs: &[f64; 8], ys: &[f64; 8], hsq: f64) -> Near8 {
            let v = self.0;
            let dx = v.sub_f64x8(cast(*xs), v.splat_f64x8(xi));
            let dy = v.sub_f64x8(cast(*ys), v.splat_f64x8(yi));
            let r2 = v.add_f64x8(v.mul_f64x8(dx, dx), v.mul_f64x8(dy, dy));
            let below = v.cmp_lt_f64x8(r2, v.splat_f64x8(hsq));
            Near8 {
                mask: below.0,
                r2: cast::<f64x8, [f64; 8]>(r2),
            }
        }

        /// [`Lanes::hits8`]: one compare into a mask, the hits packed by `vpcompressq`.
        #[inline(always)]
        fn hits8_inline(self, (xi, yi): (f64, f64), row: Row8<'_>, lanes: u8, hsq: f64) -> Hits8 {
            let v = self.0;
            let near = self.near8_inline(xi, yi, row.xs, row.ys, hsq);
            let mask = near.mask & lanes;
            let j = v
                .avx512f
                ._mm512_cvtepu32_epi64(cast(cast::<[u32; 8], u32x8>(*row.order)));
            // Positions wrap in 32 bits, as the scalar `t0.wrapping_add(k)`.
            let positions =
                v.wrapping_add_u32x8(v.splat_u32x8(row.first), cast([0_u32, 1, 2, 3, 4, 5, 6, 7]));
            let keys = v.avx512f._mm512_or_si512(
                v.avx512f._mm512_slli_epi64::<32>(j),
                v.avx512f._mm512_cvtepu32_epi64(cast(positions)),
            );
            let hits: u64x8 = cast(v.avx512f._mm512_maskz_compress_epi64(mask, keys));
            let r2: f64x8 = cast(near.r2);
            let hit_r2: f64x8 = cast(v.avx512f._mm512_maskz_compress_pd(mask, cast(r2)));
            Hits8 {
                r2: near.r2,
                hits: cast(hits),
                hit_r2: cast(hit_r2),
                count: mask.count_ones() as usize,
            }
        }
    }
}

/// Test-only lanes: the portable instructions, packing their hits ([`Lanes::PACKS_HITS`]) with
/// [`Lanes::hits8`]'s portable loop, so that the grid's packed scan runs on any machine.
#[cfg(test)]
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct PackingPortable;

#[cfg(test)]
impl Lanes for PackingPortable {
    const PACKS_HITS: bool = true;

    fn vectorize<R>(self, f: impl FnOnce() -> R) -> R {
        f()
    }

    fn near8(self, xi: f64, yi: f64, xs: &[f64; 8], ys: &[f64; 8], hsq: f64) -> Near8 {
        Portable.near8(xi, yi, xs, ys, hsq)
    }
}

#[cfg(test)]
impl Quad for PackingPortable {
    type F4 = [f64; 4];
    const TWO_NEIGHBORS: bool = false;
    fn load4(self, lanes: [f64; 4]) -> [f64; 4] {
        lanes
    }
    fn store4(self, v: [f64; 4]) -> [f64; 4] {
        v
    }
    fn add4(self, a: [f64; 4], b: [f64; 4]) -> [f64; 4] {
        Portable.add4(a, b)
    }
    fn sub4(self, a: [f64; 4], b: [f64; 4]) -> [f64; 4] {
        Portable.sub4(a, b)
    }
    fn mul4(self, a: [f64; 4], b: [f64; 4]) -> [f64; 4] {
        Portable.mul4(a, b)
    }
    fn div4(self, a: [f64; 4], b: [f64; 4]) -> [f64; 4] {
        Portable.div4(a, b)
    }
    fn neg4(self, a: [f64; 4]) -> [f64; 4] {
        Portable.neg4(a)
    }
    fn positive4(self, a: [f64; 4]) -> [f64; 4] {
        Portable.positive4(a)
    }
    fn sqrt2(self, a: [f64; 2]) -> [f64; 2] {
        Portable.sqrt2(a)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::simd::SimdPath;
    use std::mem::{align_of, offset_of};

    #[test]
    fn the_lane_arrays_a_search_stores_whole_sit_on_64_byte_boundaries() {
        // One vector store of eight f64 lanes then never straddles a cache line or a page,
        // wherever the thread's stack puts the temporary (see `Near8`; the grid's `Eight`:
        // its own test).
        for (what, align, offsets) in [
            ("Near8", align_of::<Near8>(), vec![offset_of!(Near8, r2)]),
            (
                "Hits8",
                align_of::<Hits8>(),
                vec![
                    offset_of!(Hits8, r2),
                    offset_of!(Hits8, hits),
                    offset_of!(Hits8, hit_r2),
                ],
            ),
        ] {
            assert_eq!(align, 64, "{what}");
            for offset in offsets {
                assert_eq!(offset % 64, 0, "{what}: a lane array at byte {offset}");
            }
        }
    }

    /// Candidates at, just inside and just outside the radius, NaN, infinities, signed zeros.
    fn awkward() -> ([f64; 8], [f64; 8]) {
        let h = 16.0_f64;
        (
            [
                h,
                h - 1e-12,
                0.0,
                -0.0,
                f64::NAN,
                f64::INFINITY,
                3.0,
                11.3137084989847,
            ],
            [
                0.0,
                0.0,
                h,
                -h + 1e-9,
                0.0,
                0.0,
                f64::NEG_INFINITY,
                11.3137084989848,
            ],
        )
    }

    #[test]
    fn every_available_path_packs_the_portable_hits() {
        let (xs, ys) = awkward();
        let order = [7, 3, 90, 1, 4_000_000_000, 5, 0, 12];
        // Positions from 0 and from just below the wrap of 32 bits (the packed scan's first
        // lanes can lie before its row), every lane, a run's tail, its head, none.
        for t0 in [0, 40, u32::MAX - 2] {
            for keep in [u8::MAX, 0b0000_0111, 0b1111_1000, 0b0101_0110, 0] {
                let row = Row8 {
                    xs: &xs,
                    ys: &ys,
                    order: &order,
                    first: t0,
                };
                let want = Portable.hits8((0.0, 0.0), row, keep, 256.0);
                let near = Portable.near8(0.0, 0.0, &xs, &ys, 256.0);
                let expected: Vec<u64> = (0..8)
                    .filter(|k| near.mask & keep & (1 << k) != 0)
                    .map(|k| (u64::from(order[k]) << 32) | u64::from(t0.wrapping_add(k as u32)))
                    .collect();
                assert_eq!(
                    want.hits[..want.count],
                    expected[..],
                    "t0 {t0}, keep {keep:b}"
                );
                for path in SimdPath::available() {
                    let got = crate::with_lanes!(path.lanes().unwrap(), l => {
                        l.hits8((0.0, 0.0), row, keep, 256.0)
                    });
                    let (n, bits) = (got.count, |r: &[f64]| {
                        r.iter().map(|r| r.to_bits()).collect::<Vec<_>>()
                    });
                    assert_eq!(n, want.count, "{path}");
                    assert_eq!(
                        got.hits[..n],
                        want.hits[..n],
                        "{path}, t0 {t0}, keep {keep:b}"
                    );
                    assert_eq!(bits(&got.hit_r2[..n]), bits(&want.hit_r2[..n]), "{path}");
                    assert_eq!(bits(&got.r2), bits(&want.r2), "{path}");
                }
            }
        }
    }

    #[test]
    fn every_available_path_gives_the_portable_bits_and_mask() {
        let (xs, ys) = awkward();
        let want = Portable.near8(0.0, 0.0, &xs, &ys, 256.0);
        assert_eq!(
            want.mask & 0b1111,
            0b1010,
            "r2 = 256 is not below HSQ, 256 - eps is"
        );
        for path in SimdPath::available() {
            let got = crate::with_lanes!(path.lanes().unwrap(), l => {
                l.vectorize(#[inline(always)] || l.near8(0.0, 0.0, &xs, &ys, 256.0))
            });
            assert_eq!(got.mask, want.mask, "{path}");
            let bits = |r: [f64; 8]| r.map(f64::to_bits);
            assert_eq!(bits(got.r2), bits(want.r2), "{path}");
        }
    }

    #[test]
    fn every_available_path_tests_only_the_lanes_asked_and_leaves_the_others_infinitely_far() {
        let (xs, ys) = awkward();
        for lanes in [u8::MAX, 0b0000_0111, 0b1111_1000, 0b0101_0110, 0] {
            let near = Portable.near8(0.0, 0.0, &xs, &ys, 256.0);
            let want = Portable.near8_of((0.0, 0.0), &xs, &ys, 256.0, lanes);
            assert_eq!(want.mask, near.mask & lanes, "{lanes:b}");
            for k in 0..8 {
                let expected = if lanes & (1 << k) != 0 {
                    near.r2[k]
                } else {
                    f64::INFINITY
                };
                assert_eq!(
                    want.r2[k].to_bits(),
                    expected.to_bits(),
                    "{lanes:b}: lane {k}"
                );
            }
            for path in SimdPath::available() {
                let got = crate::with_lanes!(path.lanes().unwrap(), l => {
                    l.near8_of((0.0, 0.0), &xs, &ys, 256.0, lanes)
                });
                assert_eq!(got.mask, want.mask, "{path}");
                assert_eq!(
                    got.r2.map(f64::to_bits),
                    want.r2.map(f64::to_bits),
                    "{path}"
                );
            }
        }
    }

    #[test]
    fn every_available_path_compares_and_packs_lanes_of_indices_as_the_portable_path() {
        let v = [7, 3, 90, 3, 4_000_000_000, 5, 0, 3];
        assert_eq!(Portable.ne8(v, 3), 0b0111_0101);
        assert_eq!(
            Portable.compress8(v, 0b1001_0110),
            [3, 90, 4_000_000_000, 3, 0, 0, 0, 0]
        );
        assert_eq!(Portable.compress8(v, u8::MAX), v);
        assert_eq!(Portable.compress8(v, 0), [0; 8]);
        let mut sixteen = [u32::MAX; 16];
        sixteen[..8].copy_from_slice(&v);
        assert_eq!(Portable.below16(sixteen, 5), 0b0000_0000_1100_1010);
        assert_eq!(Portable.below16(sixteen, u32::MAX), 0x00ff);
        for path in SimdPath::available() {
            for x in [3, 0, 4_000_000_000, 11] {
                let got = crate::with_lanes!(path.lanes().unwrap(), l => l.ne8(v, x));
                assert_eq!(got, Portable.ne8(v, x), "{path}: {x}");
            }
            for mask in 0..=u8::MAX {
                let got = crate::with_lanes!(path.lanes().unwrap(), l => l.compress8(v, mask));
                assert_eq!(got, Portable.compress8(v, mask), "{path}: {mask:08b}");
            }
            // The second half's last lanes are padding (u32::MAX), as the rank sort pads.
            let sixteen: [u32; 16] = std::array::from_fn(|k| {
                if k < 13 {
                    v[k % 8] ^ (k as u32 >> 3)
                } else {
                    u32::MAX
                }
            });
            for x in [0, 3, 4, 5, 91, 4_000_000_000, u32::MAX] {
                let got = crate::with_lanes!(path.lanes().unwrap(), l => l.below16(sixteen, x));
                assert_eq!(got, Portable.below16(sixteen, x), "{path}: {x}");
            }
        }
    }
}
