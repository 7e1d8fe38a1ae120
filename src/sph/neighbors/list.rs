//! Each particle's neighbours, found once per step by the density pass and reused by the force
//! pass, so a step scans for candidates once instead of twice.
//!
//! A particle has a fixed number of slots ([`SLOTS`] for Müller's presets,
//! [`WCSPH_SLOTS`] for `wcsph`, whose kernel reaches about 21 fluid neighbours and as many
//! wall particles in a corner). Its count is the true number of neighbours (j ≠ i within the
//! search radius); the list holds at most `slots - 1` of them (the last slot is scratch, so a
//! pass can write every hit without branching). When the count is higher the list is
//! incomplete and the passes that read it ask the search again for that particle. Either
//! way the same j are visited in the same order.

use sph_strategies::Split;

/// Neighbour slots per particle of Müller's presets (128 bytes). Dam-break particles have
/// about 5–15 neighbours; piles in the corners can have more, and take the slower path.
///
/// Narrower lists were measured (8 and 16 slots from 10⁵ particles on, 36 or 68 bytes): a
/// 10⁶-particle dam at rest stepped 30 % faster, but a 10⁵-particle dam in motion (200 steps)
/// 45 % slower, its many particles with more neighbours than slots searched twice a step.
pub const SLOTS: usize = 32;

/// Neighbour slots per particle of the `wcsph` preset (256 bytes).
pub const WCSPH_SLOTS: usize = 64;

/// Every particle's neighbour count and slots.
#[derive(Debug, Clone, Default)]
pub struct NeighborLists {
    /// Neighbours of particle i (excluding i), possibly more than the slots hold.
    pub count: Vec<u32>,
    /// Particle i's neighbours are `slots[i * width..][..count[i]]`, increasing, when
    /// `count[i] < width`.
    pub slots: Vec<u32>,
    /// Slots per particle.
    width: usize,
}

impl NeighborLists {
    /// Room for `n` particles of [`SLOTS`] slots each.
    pub fn new(n: usize) -> Self {
        Self::with_slots(n, SLOTS)
    }

    /// Room for `n` particles of `width` slots each.
    pub fn with_slots(n: usize, width: usize) -> Self {
        NeighborLists {
            count: written_zeros(n),
            slots: written_zeros(n * width),
            width,
        }
    }

    /// The counts and the slots, to be cut per particle in lockstep with other per-particle
    /// outputs.
    pub fn split_mut(&mut self) -> (&mut [u32], SlotsMut<'_>) {
        let slots = SlotsMut {
            slots: &mut self.slots,
            width: self.width,
        };
        (&mut self.count, slots)
    }

    /// Particle i's neighbours in increasing index, or `None` when they did not fit.
    #[inline]
    pub fn of(&self, i: usize) -> Option<&[u32]> {
        let count = self.count[i] as usize;
        let w = self.width;
        (count < w).then(|| &self.slots[i * w..i * w + count])
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
pub struct SlotsMut<'a> {
    slots: &'a mut [u32],
    width: usize,
}

impl SlotsMut<'_> {
    /// The slots of the k-th particle of this run.
    #[inline]
    pub fn particle(&mut self, k: usize) -> &mut [u32] {
        &mut self.slots[k * self.width..(k + 1) * self.width]
    }
}

impl Split for SlotsMut<'_> {
    fn len(&self) -> usize {
        self.slots.len() / self.width
    }

    fn split_at(self, mid: usize) -> (Self, Self) {
        let (a, b) = self.slots.split_at_mut(mid * self.width);
        (
            SlotsMut {
                slots: a,
                width: self.width,
            },
            SlotsMut {
                slots: b,
                width: self.width,
            },
        )
    }
}

/// `n` zeros written now, not `vec![0; n]`: that one takes fresh pages from the OS which are
/// only mapped at their first write — inside the first timed step, where a large run would
/// pay for page faults instead of physics.
pub(crate) fn written_zeros<T: Copy + Default>(n: usize) -> Vec<T> {
    let mut v = Vec::with_capacity(n);
    v.resize(n, T::default());
    v
}
