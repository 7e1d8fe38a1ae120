//! How the grid's neighbour lists name a neighbour, and which naming a run gets.
//!
//! - **By position** (`u8`): a hit's position among the particle's candidates, counted row by
//!   row through its 3×3 block. One byte a slot, but reading it back means finding the block
//!   again (from the particle's position) and picking the row.
//! - **By index** (`u32`): the neighbour's index, read back as it is. Four bytes a slot.
//!
//! Both visit the same neighbours in the same order, so both give the same bits. Index keys
//! cost three bytes a slot more and save the force pass the decoding: at N = 1000 (the
//! reference run) the force pass took a third less time (`bench-sph trace --neighbors grid
//! --strategy seq`, 6 runs of each interleaved: 37–43 ms against 53–64 ms over 1000 steps)
//! and the whole run about 10 % less. A run gets index keys while its lists in them fit in [`INDEX_KEYS_MAX_BYTES`],
//! where they stay in a core's cache next to the particles; larger runs, whose lists would
//! go out to memory, get the one-byte keys.

use crate::sph::neighbors::ListKey;

/// The most bytes a run's lists may take in index keys (512 KiB: at most half of a 1 MiB L2
/// cache, and a quarter of this VM's 2 MiB). Müller's 32 slots get index keys up to 4096 particles, `wcsph`'s 64
/// slots up to 2048 particles, walls included.
pub const INDEX_KEYS_MAX_BYTES: usize = 512 << 10;

/// How a grid's lists name neighbours.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GridKeys {
    /// By position among the particle's candidates (`u8`).
    Position,
    /// By index (`u32`).
    Index,
}

impl GridKeys {
    /// The keys of a grid whose lists have `listed` particles of `width` slots each: index
    /// keys while they fit in [`INDEX_KEYS_MAX_BYTES`].
    pub fn for_lists(listed: usize, width: usize) -> GridKeys {
        let index_bytes = listed
            .saturating_mul(width)
            .saturating_mul(size_of::<u32>());
        if index_bytes <= INDEX_KEYS_MAX_BYTES {
            GridKeys::Index
        } else {
            GridKeys::Position
        }
    }

    /// Bytes a list slot takes.
    pub fn slot_bytes(self) -> usize {
        match self {
            GridKeys::Position => size_of::<u8>(),
            GridKeys::Index => size_of::<u32>(),
        }
    }
}

/// A key type the grid can list neighbours in: `u8` names them by position, `u32` by index.
pub trait GridKey: ListKey {
    /// Whether a key is the neighbour's index (else its position among the candidates).
    const BY_INDEX: bool;
}

impl GridKey for u8 {
    const BY_INDEX: bool = false;
}

impl GridKey for u32 {
    const BY_INDEX: bool = true;
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sph::neighbors::{SLOTS, WCSPH_SLOTS};

    #[test]
    fn lists_get_index_keys_while_they_fit_in_the_cache_budget() {
        assert_eq!(GridKeys::for_lists(1000, SLOTS), GridKeys::Index);
        assert_eq!(GridKeys::for_lists(4096, SLOTS), GridKeys::Index);
        assert_eq!(GridKeys::for_lists(4097, SLOTS), GridKeys::Position);
        assert_eq!(GridKeys::for_lists(10_000, SLOTS), GridKeys::Position);
        let most = INDEX_KEYS_MAX_BYTES / (4 * WCSPH_SLOTS);
        assert_eq!(GridKeys::for_lists(most, WCSPH_SLOTS), GridKeys::Index);
        assert_eq!(
            GridKeys::for_lists(most + 1, WCSPH_SLOTS),
            GridKeys::Position
        );
        assert_eq!(GridKeys::for_lists(usize::MAX, 2), GridKeys::Position);
    }
}
