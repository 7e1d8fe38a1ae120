//! Each particle's neighbours, found once per step by the density pass and reused by the force
//! pass, so a step scans for candidates once instead of twice.
//!
//! A list names its neighbours by the search's keys ([`ListKey`]): all-pairs by index (`u32`),
//! the grid by index in a small run and by position among the particle's candidates in a
//! large one (`u8`, a quarter of the memory; see
//! [`GridKeys`](crate::sph::neighbors::GridKeys)).
//!
//! A particle has a fixed number of slots ([`SLOTS`] for Müller's presets,
//! [`WCSPH_SLOTS`] for `wcsph`, whose lists reach about 20). Its count is the number of neighbours listed (j ≠ i within the
//! search radius); the list holds at most `slots - 1` of them (the last slot is scratch, so a
//! pass can write every hit without branching). When there are more, or a neighbour's key does
//! not fit the list's key type, the list is not used: the passes that read it ask the search
//! again for that particle. Either way the same j are visited in the same order.

use sph_strategies::Split;

/// Neighbour slots per particle of Müller's presets (32 bytes with the grid's one-byte keys,
/// 128 with `u32` indices: all-pairs', and the grid's in small runs). Dam-break particles have about 5–15 neighbours; piles in the corners can have
/// more, and take the slower path.
///
/// Narrower lists of `u32` indices were measured (8 and 16 slots from 10⁵ particles on, 36 or
/// 68 bytes): a 10⁶-particle dam at rest stepped 30 % faster, but a 10⁵-particle dam in motion
/// (200 steps) 45 % slower, its many particles with more neighbours than slots searched twice
/// a step. One-byte keys keep 32 slots in the bytes 8 indices took.
pub const SLOTS: usize = 32;

/// Neighbour slots per particle of the `wcsph` preset: its lists reach 2.15 h (2.8 spacings:
/// 20 neighbours in the initial lattice, about as many in the flow), and are read by index
/// (`u32`), so a slot costs four bytes at every size; 32 slots made a run at R = 200 take 1.51×
/// the memory of the lists built every step (one-byte keys, 64 slots), 28 about 1.45×.
pub const WCSPH_SLOTS: usize = 28;

/// A count that marks a list as not usable (a key did not fit).
const UNLISTED: u32 = u32::MAX;

/// How a list names a neighbour: a key that the search hands out with each hit and turns
/// back into the neighbour's index.
pub trait ListKey: Copy + Default + std::fmt::Debug + Send + Sync + 'static {
    /// The largest key this type holds.
    const MAX: u32;

    /// `key` as this type (truncated: only keys up to [`ListKey::MAX`] are ever read back).
    fn truncate(key: u32) -> Self;

    /// The key.
    fn get(self) -> u32;
}

impl ListKey for u8 {
    const MAX: u32 = u8::MAX as u32;

    #[inline(always)]
    fn truncate(key: u32) -> Self {
        key as u8
    }

    #[inline(always)]
    fn get(self) -> u32 {
        self.into()
    }
}

impl ListKey for u32 {
    const MAX: u32 = u32::MAX;

    #[inline(always)]
    fn truncate(key: u32) -> Self {
        key
    }

    #[inline(always)]
    fn get(self) -> u32 {
        self
    }
}

/// Writes one particle's list: every hit goes to the next free slot (or the scratch slot once
/// the list is full), without a branch, and only those kept advance the count.
#[derive(Debug)]
pub struct ListWriter<'a, K> {
    slots: &'a mut [K],
    /// The scratch slot: `slots.len() - 1`.
    scratch: usize,
    len: usize,
    fits: bool,
}

impl<'a, K: ListKey> ListWriter<'a, K> {
    /// Writes into `slots` (at least one: the scratch slot).
    ///
    /// # Panics
    /// If `slots` is empty.
    #[inline(always)]
    pub fn new(slots: &'a mut [K]) -> Self {
        // Found here once, so that each push's slot is known to lie in `slots`.
        let scratch = slots.len().checked_sub(1).expect("a scratch slot");
        ListWriter {
            slots,
            scratch,
            len: 0,
            fits: true,
        }
    }

    /// Writes `key`; it stays in the list only when `keep` (the next write goes over it
    /// otherwise).
    #[inline(always)]
    pub fn push(&mut self, key: u32, keep: bool) {
        self.slots[self.len.min(self.scratch)] = K::truncate(key);
        self.fits &= !keep | (key <= K::MAX);
        self.len += usize::from(keep);
    }

    /// Writes the keys whose bit is set in `keep`, in lane order, where `packed` holds them at
    /// its front ([`Lanes::compress8`](crate::simd::Lanes::compress8)); `keys` are all eight,
    /// for the check that the kept ones fit the key type.
    #[inline(always)]
    pub fn push_eight(&mut self, keys: &[u32; 8], packed: &[u32; 8], keep: u8) {
        let over = (0..8).fold(0u8, |m, k| m | (u8::from(keys[k] > K::MAX) << k));
        self.fits &= over & keep == 0;
        let count = keep.count_ones() as usize;
        if self.len + 8 <= self.scratch {
            let to: &mut [K; 8] = (&mut self.slots[self.len..self.len + 8])
                .try_into()
                .expect("eight slots");
            *to = packed.map(K::truncate);
        } else {
            for &key in &packed[..count] {
                self.slots[self.len.min(self.scratch)] = K::truncate(key);
                self.len += 1;
            }
            return;
        }
        self.len += count;
    }

    /// The count to store: the neighbours kept, or a count no list holds when a key did not
    /// fit.
    #[inline(always)]
    pub fn finish(self) -> u32 {
        if self.fits { self.len as u32 } else { UNLISTED }
    }
}

/// Every particle's neighbour count and slots, in keys of type `K`.
#[derive(Debug, Clone, Default)]
pub struct NeighborLists<K> {
    /// Neighbours of particle i (excluding i) listed, possibly more than the slots hold, or
    /// more than any list holds when the list is not usable.
    pub count: Vec<u32>,
    /// Particle i's neighbours are `slots[i * width..][..count[i]]`, in the search's visit order,
    /// when `count[i] < width`.
    pub slots: Vec<K>,
    /// Slots per particle.
    width: usize,
}

impl<K: ListKey> NeighborLists<K> {
    /// Room for `n` particles of `width` slots each.
    pub fn with_slots(n: usize, width: usize) -> Self {
        NeighborLists {
            count: written_zeros(n),
            slots: written_zeros(n * width),
            width,
        }
    }

    /// Particles with a list.
    pub fn len(&self) -> usize {
        self.count.len()
    }

    /// Whether no particle has a list.
    pub fn is_empty(&self) -> bool {
        self.count.is_empty()
    }

    /// Slots per particle.
    pub fn width(&self) -> usize {
        self.width
    }

    /// The counts and the slots, to be cut per particle in lockstep with other per-particle
    /// outputs.
    pub fn split_mut(&mut self) -> (&mut [u32], SlotsMut<'_, K>) {
        let slots = SlotsMut {
            slots: &mut self.slots,
            width: self.width,
        };
        (&mut self.count, slots)
    }

    /// Particle i's neighbours (their keys) in the search's visit order, or `None` when they did
    /// not fit.
    #[inline]
    pub fn of(&self, i: usize) -> Option<&[K]> {
        let count = self.count[i] as usize;
        let w = self.width;
        (count < w).then(|| &self.slots[i * w..i * w + count])
    }

    /// Particles whose list did not fit at its last writing (its passes search again).
    pub fn unusable(&self) -> usize {
        self.count
            .iter()
            .filter(|&&c| c as usize >= self.width)
            .count()
    }

    /// Heap bytes held (capacity): what `scene::memory::estimate` must predict (its test
    /// compares the two).
    pub fn heap_bytes(&self) -> usize {
        4 * self.count.capacity() + size_of::<K>() * self.slots.capacity()
    }
}

/// The slots of a run of consecutive particles, split per particle in lockstep with other
/// per-particle outputs.
#[derive(Debug)]
pub struct SlotsMut<'a, K> {
    slots: &'a mut [K],
    width: usize,
}

impl<K: ListKey> SlotsMut<'_, K> {
    /// A writer of the k-th particle's list of this run.
    #[inline]
    pub fn particle(&mut self, k: usize) -> ListWriter<'_, K> {
        ListWriter::new(&mut self.slots[k * self.width..(k + 1) * self.width])
    }
}

impl<K: ListKey> Split for SlotsMut<'_, K> {
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

#[cfg(test)]
mod tests {
    use super::*;

    fn written(width: usize, pushes: &[(u32, bool)]) -> (u32, Vec<u8>) {
        let mut slots = vec![0u8; width];
        let mut list = ListWriter::new(&mut slots);
        for &(key, keep) in pushes {
            list.push(key, keep);
        }
        (list.finish(), slots)
    }

    #[test]
    fn a_kept_key_past_the_type_leaves_the_list_unusable() {
        let (count, _) = written(8, &[(3, true), (256, true), (4, true)]);
        assert_eq!(count, UNLISTED);
    }

    #[test]
    fn a_key_past_the_type_that_is_not_kept_changes_nothing() {
        // The particle itself (or a wall that walls do not read) is written, then written over.
        let (count, slots) = written(8, &[(3, true), (300, false), (5, true)]);
        assert_eq!(count, 2);
        assert_eq!(&slots[..2], [3, 5]);
    }

    #[test]
    fn a_list_is_read_back_up_to_one_short_of_its_slots_and_not_beyond() {
        let mut lists = NeighborLists::<u8>::with_slots(2, 4);
        let (count, mut slots) = lists.split_mut();
        for (c, keys) in count.iter_mut().zip([&[1u32, 2, 3][..], &[1, 2, 3, 4]]) {
            let mut list = slots.particle(0);
            keys.iter().for_each(|&k| list.push(k, true));
            *c = list.finish();
            slots = slots.split_at(1).1;
        }
        assert_eq!(lists.of(0), Some(&[1u8, 2, 3][..]));
        assert_eq!(lists.of(1), None);
    }

    #[test]
    fn eight_keys_at_once_are_written_as_one_at_a_time_up_to_a_full_list() {
        let keys = [3u32, 9, 300, 12, 0, 255, 256, 40];
        let packed = |keep: u8| {
            let mut p = [0; 8];
            let kept: Vec<u32> = (0..8)
                .filter(|k| keep & (1 << k) != 0)
                .map(|k| keys[k])
                .collect();
            p[..kept.len()].copy_from_slice(&kept);
            p
        };
        // From empty to nearly full and beyond (width 12: 11 listed at most), keys that fit a
        // byte and keys that do not, kept and not.
        for before in [0usize, 2, 4, 9, 11, 14] {
            for keep in [
                0u8,
                0b0000_0001,
                0b1011_1011,
                0b0100_0000,
                0b0010_1101,
                u8::MAX,
            ] {
                let mut one = vec![0u8; 12];
                let mut all = vec![0u8; 12];
                let (mut a, mut b) = (ListWriter::new(&mut one), ListWriter::new(&mut all));
                for k in 0..before as u32 {
                    a.push(k, true);
                    b.push(k, true);
                }
                for (k, &key) in keys.iter().enumerate() {
                    a.push(key, keep & (1 << k) != 0);
                }
                b.push_eight(&keys, &packed(keep), keep);
                let count = a.finish();
                assert_eq!(b.finish(), count, "{before} before, keep {keep:08b}");
                // A list is read only when its count is below its width.
                let listed = if (count as usize) < 12 {
                    count as usize
                } else {
                    0
                };
                assert_eq!(
                    all[..listed],
                    one[..listed],
                    "{before} before, keep {keep:08b}"
                );
            }
        }
    }
}
