//! Outputs that can be cut into disjoint pieces: one mutable slice, or several of equal
//! length cut in lockstep (a pass that writes `rho` and `p` hands over `(&mut rho, &mut p)`).

/// A set of output arrays, all of the same length, that can be split at an index into two
/// disjoint halves. Implemented for `&mut [T]` and for tuples of up to four of them.
///
/// Splitting never copies: it is `split_at_mut` on every member, so a strategy hands each
/// thread its own borrow and no `unsafe` is needed.
pub trait Split: Send + Sized {
    /// Number of elements (particles) covered; every member has this length.
    fn len(&self) -> usize;

    /// Whether the outputs cover no element.
    fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Cuts at `mid` (`mid <= len`) into `[0, mid)` and `[mid, len)`.
    fn split_at(self, mid: usize) -> (Self, Self);
}

impl<T: Send> Split for &mut [T] {
    fn len(&self) -> usize {
        <[T]>::len(self)
    }

    fn split_at(self, mid: usize) -> (Self, Self) {
        self.split_at_mut(mid)
    }
}

impl<A: Split, B: Split> Split for (A, B) {
    fn len(&self) -> usize {
        assert_eq!(
            self.0.len(),
            self.1.len(),
            "outputs split in lockstep must have equal lengths"
        );
        self.0.len()
    }

    fn split_at(self, mid: usize) -> (Self, Self) {
        let (a0, a1) = self.0.split_at(mid);
        let (b0, b1) = self.1.split_at(mid);
        ((a0, b0), (a1, b1))
    }
}

impl<A: Split, B: Split, C: Split, D: Split> Split for (A, B, C, D) {
    fn len(&self) -> usize {
        let n = self.0.len();
        assert!(
            self.1.len() == n && self.2.len() == n && self.3.len() == n,
            "outputs split in lockstep must have equal lengths"
        );
        n
    }

    fn split_at(self, mid: usize) -> (Self, Self) {
        let (a0, a1) = self.0.split_at(mid);
        let (b0, b1) = self.1.split_at(mid);
        let (c0, c1) = self.2.split_at(mid);
        let (d0, d1) = self.3.split_at(mid);
        ((a0, b0, c0, d0), (a1, b1, c1, d1))
    }
}

/// Cuts `out` into `min(k, len)` balanced chunks (sizes differ by at most one, larger ones
/// first), returned in order with the index of each chunk's first element.
/// `k = 0` is treated as 1; an empty output gives no chunk.
pub fn balanced_chunks<O: Split>(out: O, k: usize) -> Vec<(usize, O)> {
    let n = out.len();
    let k = k.max(1).min(n);
    let mut chunks = Vec::with_capacity(k);
    let mut rest = out;
    let mut first = 0;
    for c in 0..k {
        let size = n / k + usize::from(c < n % k);
        let (head, tail) = rest.split_at(size);
        chunks.push((first, head));
        first += size;
        rest = tail;
    }
    chunks
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn balanced_chunks_cover_every_index_once_with_sizes_differing_by_at_most_one() {
        for n in [0usize, 1, 2, 7, 10, 999, 1000] {
            for k in [1usize, 2, 3, 7, 64, 1000, 2000] {
                let mut a = vec![0u32; n];
                let mut b = vec![0u32; n];
                let chunks = balanced_chunks((&mut a[..], &mut b[..]), k);
                assert_eq!(chunks.len(), k.min(n));
                let sizes: Vec<usize> = chunks.iter().map(|(_, c)| c.len()).collect();
                if let (Some(max), Some(min)) = (sizes.iter().max(), sizes.iter().min()) {
                    assert!(max - min <= 1, "n={n} k={k} sizes={sizes:?}");
                }
                let mut expected_first = 0;
                for (first, (ca, cb)) in chunks {
                    assert_eq!(first, expected_first);
                    for (off, (va, vb)) in ca.iter_mut().zip(cb.iter_mut()).enumerate() {
                        *va += (first + off) as u32 + 1;
                        *vb += 1;
                    }
                    expected_first += ca.len();
                }
                assert_eq!(expected_first, n);
                assert!(a.iter().enumerate().all(|(i, &v)| v == i as u32 + 1));
                assert!(b.iter().all(|&v| v == 1));
            }
        }
    }
}
