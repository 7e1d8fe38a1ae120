//! A stable fingerprint of a state: FNV-1a (64-bit) over the little-endian bytes of the f64
//! bits of x, y, vx, vy of particle 0, then particle 1, and so on. Two states have the same
//! checksum when (barring a collision) every position and velocity has the same bits.

use crate::sph::state::State;

const FNV_OFFSET: u64 = 0xcbf2_9ce4_8422_2325;
const FNV_PRIME: u64 = 0x0000_0100_0000_01b3;

/// FNV-1a over `bytes`, continuing from `hash`.
fn fnv1a(mut hash: u64, bytes: &[u8]) -> u64 {
    for &b in bytes {
        hash ^= u64::from(b);
        hash = hash.wrapping_mul(FNV_PRIME);
    }
    hash
}

/// FNV-1a (64-bit) of `bytes`: a stable fingerprint (the same on every machine and build).
pub fn fingerprint(bytes: &[u8]) -> u64 {
    fnv1a(FNV_OFFSET, bytes)
}

/// The state's checksum.
pub fn checksum(state: &State) -> u64 {
    (0..state.len()).fold(FNV_OFFSET, |h, i| {
        [state.x[i], state.y[i], state.vx[i], state.vy[i]]
            .iter()
            .fold(h, |h, v| fnv1a(h, &v.to_bits().to_le_bytes()))
    })
}

/// The checksum as 16 lowercase hex digits, as printed and written to CSV.
pub fn checksum_hex(state: &State) -> String {
    format!("{:016x}", checksum(state))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fnv1a_matches_its_published_test_vectors() {
        assert_eq!(fnv1a(FNV_OFFSET, b""), 0xcbf29ce484222325);
        assert_eq!(fnv1a(FNV_OFFSET, b"a"), 0xaf63dc4c8601ec8c);
        assert_eq!(fnv1a(FNV_OFFSET, b"foobar"), 0x85944171f73967e8);
    }

    #[test]
    fn one_ulp_or_a_swap_of_particles_changes_the_checksum() {
        let a = State::from_kinematics(vec![1.0, 2.0], vec![3.0, 4.0], vec![0.0; 2], vec![0.0; 2]);
        let mut b = a.clone();
        b.x[1] = f64::from_bits(b.x[1].to_bits() + 1);
        let swapped =
            State::from_kinematics(vec![2.0, 1.0], vec![4.0, 3.0], vec![0.0; 2], vec![0.0; 2]);
        assert_ne!(checksum(&a), checksum(&b));
        assert_ne!(checksum(&a), checksum(&swapped));
        assert_eq!(checksum_hex(&a).len(), 16);
    }
}
