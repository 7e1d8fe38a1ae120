//! Each particle's neighbours, found once per step by the density pass and reused by the force
//! pass, so a step scans for candidates once instead of twice.
//!
//! A particle has [`SLOTS`] slots. Its count is the true number of neighbours (j ≠ i with
//! `r2 < HSQ`); the list holds at most `SLOTS - 1` of them (the last slot is scratch, so
//! the density pass can write every hit without branching). When the count is higher the
//! list is incomplete and the force pass asks the search again for that particle. Either way the same j are visited in the same order.

use sph_strategies::Split;

/// Neighbour slots per particle (128 bytes). Dam-break particles have about 5–15 neighbours;
/// piles in the corners can have more, and take the slower path.
pub const SLOTS: usize = 32;

/// Every particle's neighbour count and slots.
#[derive(Debug, Clone, Default)]
pub struct NeighborLists {
    /// Neighbours of particle i (excluding i), possibly more than [`SLOTS`].
    pub count: Vec<u32>,
    /// Particle i's neighbours are `slots[i * SLOTS..][..count[i]]`, increasing, when
    /// `count[i] < SLOTS`.
    pub slots: Vec<u32>,
}

impl NeighborLists {
    /// Room for `n` particles.
    pub fn new(n: usize) -> Self {
        NeighborLists {
            count: vec![0; n],
            slots: vec![0; n * SLOTS],
        }
    }

    /// Particle i's neighbours in increasing index, or `None` when they did not fit.
    #[inline]
    pub fn of(&self, i: usize) -> Option<&[u32]> {
        let count = self.count[i] as usize;
        (count < SLOTS).then(|| &self.slots[i * SLOTS..i * SLOTS + count])
    }

    /// Heap bytes held (capacity): what `scene::memory::estimate` must predict (its test
    /// compares the two).
    pub fn heap_bytes(&self) -> usize {
        4 * (self.count.capacity() + self.slots.capacity())
    }
}

/// The slots of a run of consecutive particles, split per particle in lockstep with other
/// per-particle outputs.
#[derive(Debug)]
pub struct SlotsMut<'a>(pub &'a mut [u32]);

impl SlotsMut<'_> {
    /// The slots of the k-th particle of this run.
    #[inline]
    pub fn particle(&mut self, k: usize) -> &mut [u32] {
        &mut self.0[k * SLOTS..(k + 1) * SLOTS]
    }
}

impl Split for SlotsMut<'_> {
    fn len(&self) -> usize {
        self.0.len() / SLOTS
    }

    fn split_at(self, mid: usize) -> (Self, Self) {
        let (a, b) = self.0.split_at_mut(mid * SLOTS);
        (SlotsMut(a), SlotsMut(b))
    }
}
