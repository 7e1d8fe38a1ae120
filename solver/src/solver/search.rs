//! The concrete neighbour search (and SIMD lanes) inside a run's `AnyNeighbors`, picked once
//! per pass so that the models' passes are monomorphised per search, not dispatched per
//! particle.

/// Runs `$body` with `$nb` bound to the concrete search inside `$any` (a `&mut AnyNeighbors`)
/// and `$lists` to its lists, so that the code in `$body` is monomorphised per search (picked
/// once per call, not per particle).
macro_rules! with_search {
    ($any:expr, ($nb:ident, $lists:ident) => $body:expr) => {{
        use $crate::sph::neighbors::{AnyNeighbors, Searched};
        match $any {
            AnyNeighbors::AllPairs(Searched {
                search: $nb,
                lists: $lists,
            }) => $body,
            AnyNeighbors::GridByPosition(Searched {
                search: $nb,
                lists: $lists,
            }) => $body,
            AnyNeighbors::GridByIndex(Searched {
                search: $nb,
                lists: $lists,
            }) => $body,
            AnyNeighbors::GridInCellOrder(Searched {
                search: $nb,
                lists: $lists,
            }) => $body,
            AnyNeighbors::GridByIndexInCellOrder(Searched {
                search: $nb,
                lists: $lists,
            }) => $body,
        }
    }};
}

/// [`with_search!`], and `$l` bound to the lanes the search tests candidates in: the run's
/// SIMD path for all-pairs; for the grid AVX-512's, which packs a row's hits eight candidates
/// at a time (where the grid's `scans_packed` says so), and otherwise the portable lanes: the
/// grid tests its few candidates per row one by one there, compiled for the target. Müller's
/// force pass, which searches only for a pile, gets the run's path on every search.
macro_rules! with_search_lanes {
    ($any:expr, $lanes:expr, ($nb:ident, $lists:ident, $l:ident) => $body:expr) => {{
        use $crate::sph::neighbors::{AnyNeighbors, Searched};
        match $any {
            AnyNeighbors::AllPairs(Searched { search: $nb, lists: $lists }) => {
                $crate::with_lanes!($lanes, $l => $body)
            }
            // Every grid (`with_search!`'s all-pairs arm is never taken here).
            #[cfg(target_arch = "x86_64")]
            grid if matches!($lanes, $crate::simd::AnyLanes::Avx512(_)) => {
                let $crate::simd::AnyLanes::Avx512($l) = $lanes else { unreachable!() };
                $crate::solver::search::with_search!(grid, ($nb, $lists) => $body)
            }
            grid => {
                let $l = $crate::simd::Portable;
                $crate::solver::search::with_search!(grid, ($nb, $lists) => $body)
            }
        }
    }};
}

pub(crate) use with_search;
pub(crate) use with_search_lanes;
