//! A particle's hits while the grid collects them and puts them in order: the working memory
//! a search call reuses ([`GridScratch`]) and the sorts.
//!
//! A hit is one word, the neighbour's index above its position among the particle's
//! candidates ([`hit`]): indices are distinct, so sorting the words sorts by index, and the low
//! word alone gives the candidates' order.

use crate::simd::Lanes;

/// Candidates of one particle collected in [`GridScratch`]; a particle with more (a pile in a
/// corner) collects its hits in a vector. Müller's presets have about 12–30 candidates, `wcsph`
/// up to about 100 next to a wall.
pub(super) const INLINE_HITS: usize = 128;

// The search indexes its hits modulo INLINE_HITS: a mask, not a division.
const _: () = assert!(INLINE_HITS.is_power_of_two());

/// Blocks of up to this many candidates are scanned in one loop rather than row by row: see
/// the grid's `for_each_within`.
pub(super) const ONE_LOOP_MAX: u32 = 32;

/// The most hits put in order by [`rank_sort`]: each hit is compared with this many indices,
/// in whole registers (two of sixteen on AVX-512), so more (`wcsph`'s lists hold about 20–28
/// within their radius, a search of 2h near a wall up to about 45) are sorted by comparison
/// instead. Either gives the one increasing order of distinct indices.
pub(super) const RANK_SORT_MAX: usize = 32;

// The rank sort compares two registers of sixteen.
const _: () = assert!(RANK_SORT_MAX == 32);

/// The most hits put in order by [`sort_small`], whose work is fixed: no branch depends on the
/// number of hits. Müller's particles have about 6 hits (self included) once the dam has
/// fallen, 13 while it falls.
pub(super) const SMALL: usize = 8;

/// Working memory of the grid's search for one particle, made once per run of particles (a
/// chunk) and reused: made per particle, its 2 KiB were zeroed per particle, a tenth of the
/// reference run's instructions.
#[derive(Debug, Clone)]
pub struct GridScratch {
    /// The hits collected: every candidate is written at the next free place, which only a hit
    /// takes. Up to [`SMALL`] hits are followed by [`SMALL`] places of padding for
    /// [`in_order`] and [`sort_small`] (within the first `2 × SMALL`). The eight places past
    /// [`INLINE_HITS`] take the packed scan's whole stores of eight.
    pub(super) hits: [u64; INLINE_HITS + 8],
    /// Each candidate's squared distance, by its position in the block; the hits', by hit,
    /// where the packed scan collects them for a grid summing in cell order.
    pub(super) r2: [f64; INLINE_HITS + 8],
    /// The hits put in order by [`rank_sort`].
    pub(super) ranked: [u64; RANK_SORT_MAX],
}

impl Default for GridScratch {
    fn default() -> Self {
        GridScratch {
            hits: [0; INLINE_HITS + 8],
            r2: [0.0; INLINE_HITS + 8],
            ranked: [0; RANK_SORT_MAX],
        }
    }
}

/// Neighbour `j`, the candidate at `position` in its block, as one sortable word.
#[inline(always)]
pub(super) fn hit(j: u32, position: u32) -> u64 {
    (u64::from(j) << 32) | u64::from(position)
}

/// The index of the neighbour a hit names.
#[inline(always)]
pub(super) fn index_of(hit: u64) -> u32 {
    (hit >> 32) as u32
}

/// The position among its block's candidates of the neighbour a hit names.
#[inline(always)]
pub(super) fn position_of(hit: u64) -> u32 {
    hit as u32
}

/// Puts the hits `src` (at most [`RANK_SORT_MAX`], of distinct indices) in increasing order
/// into `dst` by counting, for each, how many indices are smaller: quadratic but branch-free,
/// which beats branching sorts on a few dozen. The indices are compared as 32-bit words, all
/// [`RANK_SORT_MAX`] places at once in `lanes` (the places past the hits hold `u32::MAX`,
/// smaller than none), so that the count has no loop end that depends on the number of hits:
/// on AVX-512 two compares into mask registers and their population counts. (A sum of the
/// comparisons took each bit out of the mask on its own.)
#[inline(always)]
pub(super) fn rank_sort<L: Lanes>(lanes: L, src: &[u64], dst: &mut [u64]) {
    let mut indices = [u32::MAX; RANK_SORT_MAX];
    for (index, &h) in indices.iter_mut().zip(src) {
        *index = index_of(h);
    }
    let low: [u32; 16] = std::array::from_fn(|k| indices[k]);
    let high: [u32; 16] = std::array::from_fn(|k| indices[16 + k]);
    for &h in src {
        let i = index_of(h);
        let rank = lanes.below16(low, i).count_ones() + lanes.below16(high, i).count_ones();
        dst[rank as usize] = h;
    }
}

/// Whether `hits` are in increasing order, found without a branch: a fold, not `is_sorted`,
/// which is a call per particle here. Padding (`u64::MAX`, equal to each other) counts as in
/// order after the hits; the hits themselves are distinct.
#[inline(always)]
pub(super) fn in_order(hits: &[u64]) -> bool {
    hits.windows(2).fold(true, |ok, w| ok & (w[0] <= w[1]))
}

/// Puts the first [`SMALL`] hits in increasing order: the hits and, from some place on, padding
/// of `u64::MAX` (which stays last). A sorting network: a fixed sequence of compare-exchanges
/// with no branch (a sort whose work varies with the number of hits mispredicts its loops'
/// ends; these hits number about 6).
#[inline(always)]
pub(super) fn sort_small(hits: &mut [u64; SMALL]) {
    // A network of 19 compare-exchanges in 6 layers, the fewest for 8 inputs. Written out
    // (a loop over pairs kept them in memory, each load bounds-checked), on a copy the
    // compiler keeps in registers.
    macro_rules! exchange {
        ($v:ident: $(($a:literal, $b:literal)),*) => {$(
            let (x, y) = ($v[$a], $v[$b]);
            $v[$a] = x.min(y);
            $v[$b] = x.max(y);
        )*};
    }
    let mut v = *hits;
    exchange!(v: (0, 2), (1, 3), (4, 6), (5, 7));
    exchange!(v: (0, 4), (1, 5), (2, 6), (3, 7));
    exchange!(v: (0, 1), (2, 3), (4, 5), (6, 7));
    exchange!(v: (2, 4), (3, 5));
    exchange!(v: (1, 4), (3, 6));
    exchange!(v: (1, 2), (3, 4), (5, 6));
    *hits = v;
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::simd::SimdPath;
    use crate::with_lanes;

    #[test]
    fn the_small_network_sorts_every_input() {
        // A network that sorts every sequence of 0s and 1s sorts every sequence (Knuth's
        // 0-1 principle): all 256 of them.
        for bits in 0u32..1 << SMALL {
            let mut v: [u64; SMALL] = std::array::from_fn(|k| u64::from((bits >> k) & 1));
            sort_small(&mut v);
            assert!(v.is_sorted(), "{bits:08b}: {v:?}");
        }
        // And hits with padding, at every length.
        let indices = [41u32, 7, 300, 2, 99, 0, 1000, 8];
        for len in 0..=SMALL {
            let mut v = [u64::MAX; SMALL];
            for (k, &j) in indices[..len].iter().enumerate() {
                v[k] = hit(j, 50 - k as u32);
            }
            let mut expected = v;
            expected.sort_unstable();
            sort_small(&mut v);
            assert_eq!(v, expected, "len {len}");
        }
    }

    #[test]
    fn hits_are_in_order_when_each_is_below_the_next_padding_included() {
        let padding = [u64::MAX; 3];
        let with_padding = |hits: &[u64]| [hits, &padding].concat();
        assert!(in_order(&with_padding(&[hit(1, 5), hit(4, 0), hit(9, 2)])));
        assert!(!in_order(&with_padding(&[hit(4, 0), hit(1, 5), hit(9, 2)])));
        assert!(!in_order(&[u64::MAX, hit(1, 0)]));
        assert!(in_order(&[]) && in_order(&padding));
    }

    #[test]
    fn a_rank_sort_orders_as_many_hits_as_it_takes() {
        // RANK_SORT_MAX distinct indices, shuffled by a fixed stride: sorted as the std sort.
        let src: Vec<u64> = (0..RANK_SORT_MAX as u32)
            .map(|k| hit((k * 13) % RANK_SORT_MAX as u32 * 7 + 1, k))
            .collect();
        let mut expected = src.clone();
        expected.sort_unstable();
        for path in SimdPath::available() {
            let mut dst = vec![0u64; RANK_SORT_MAX];
            with_lanes!(path.lanes().unwrap(), l => rank_sort(l, &src, &mut dst));
            assert_eq!(dst, expected, "{path}");
        }
    }

    #[test]
    fn a_rank_sort_orders_distinct_hits_by_index() {
        // Four hits: the other 28 places compared are padding.
        let src = [hit(9, 0), hit(3, 1), hit(12, 2), hit(4, 3)];
        for path in SimdPath::available() {
            let mut dst = [0u64; 4];
            with_lanes!(path.lanes().unwrap(), l => rank_sort(l, &src, &mut dst));
            assert_eq!(dst.map(index_of), [3, 4, 9, 12], "{path}");
            assert_eq!(dst.map(position_of), [1, 3, 0, 2], "{path}");
        }
    }
}
