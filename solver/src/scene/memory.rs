//! How much memory a run needs, and a refusal when the machine does not have it, so that a
//! huge `--n` ends as one `Error: ...` line rather than an allocation abort or the OOM killer.
//!
//! The estimate counts the arrays that grow with N, from the sizes of their element types:
//! - the particle state: [`FIELD_NAMES`]`.len()` arrays of `f64` (64 B per particle);
//! - the model's scratch: Müller's next positions and velocities (32 B per particle; see
//!   [`mueller::next_motion`]), `wcsph`'s (see [`estimate`]);
//! - the neighbour lists: a `u32` count and [`SLOTS`] slots per particle, a `u32` index each
//!   with all-pairs (132 B), and with the grid a `u8` key (36 B) or, while the lists fit in
//!   [`GridKeys`]' cache budget, a `u32` index;
//! - with `--neighbors grid`, the cell list: particle order and cell (`u32` each), sorted
//!   positions (`f64` × 2), and one `u32` start per cell of the tank and of the empty ring
//!   around it; the tank widens with N
//!   (see [`crate::models::mueller::scene`]); from 65 536 particles on, the scratch of the sort in
//!   bands ([`Grid::sort_scratch_bytes`]: a `u32` per particle and 1 KiB per 16 384).
//!
//! A unit test holds the estimate equal to what a [`crate::solver::Simulation`] allocates.
//! Fixed costs (the binary, thread stacks, a frame of an animation) are not counted: they are
//! megabytes, against the gigabytes this check is about.

use std::mem::size_of;

use crate::MAX_PARTICLES;
use crate::models::Physics;
use crate::models::Preset;
use crate::models::wcsph::kept::MOVED_BLOCK;
use crate::models::wcsph::params::WcParams;
use crate::models::{mueller, wcsph};
use crate::solver::SPEED_BLOCK;
use crate::sph::neighbors::{Grid, GridKeys, NeighborMode, SLOTS, WCSPH_SLOTS};
use crate::sph::state::FIELD_NAMES;

/// Why a run was refused.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum MemoryError {
    /// More particles than any command accepts.
    #[error("--n {n} is more than the {MAX_PARTICLES} particles any command accepts")]
    TooMany {
        /// The particle count asked for.
        n: usize,
    },
    /// More memory than the machine has available.
    #[error(
        "--n {n} needs about {} of memory ({neighbors} search); this machine has {} available",
        human_bytes(*.needs), human_bytes(*.available)
    )]
    TooLarge {
        /// The particle count asked for.
        n: usize,
        /// The neighbour search.
        neighbors: NeighborMode,
        /// Estimated bytes ([`estimate`]).
        needs: u64,
        /// Bytes available ([`available_bytes`]).
        available: u64,
    },
}

/// Bytes the arrays of a run of `n` particles of `preset` with `neighbors` search hold (see
/// the module docs). Saturates instead of overflowing, so any `n` gives an answer.
///
/// For `wcsph`, `n` is mapped to its resolution as the commands map it, and the count is of
/// fluid and wall particles: lists of [`WCSPH_SLOTS`] for every particle, its kicked velocity,
/// a 1/512 share of a displacement block and, with all-pairs, the position its list was built
/// at (the grid's own copies serve), and a density rate and a 1/256 share of a speed block
/// per fluid particle.
pub fn estimate(preset: Preset, neighbors: NeighborMode, n: usize) -> u64 {
    let (physics, domain, n, lists_of, fluid_scratch) = match preset {
        Preset::Wcsph => {
            let r = wcsph::scene::resolution_for(n);
            let fluid = wcsph::scene::dam_break_particles(r);
            let physics = Physics::from(WcParams::new(r, fluid));
            let total = fluid + wcsph::scene::wall_particles(r);
            // Per particle: its kicked velocity and, with all-pairs, where its list was built
            // (x and y each).
            let copies = if neighbors == NeighborMode::AllPairs {
                2
            } else {
                0
            };
            let kept = (2 + copies) * total as u64 + total.div_ceil(MOVED_BLOCK) as u64;
            let scratch = 8 * (fluid as u64 + fluid.div_ceil(SPEED_BLOCK) as u64 + kept);
            (physics, wcsph::scene::domain(), total, WCSPH_SLOTS, scratch)
        }
        Preset::Seed | Preset::Cpp => {
            let physics = Physics::from(preset.params());
            // The step's new positions and velocities, written beside the state's.
            let next_motion = (n as u64).saturating_mul(4 * 8);
            (
                physics,
                mueller::scene::domain(preset, n),
                n,
                SLOTS,
                next_motion,
            )
        }
    };
    let n64 = n as u64;
    // A list's count, and its slots in the search's keys: `u32` for all-pairs, and for the
    // grid those its size gets (`u32` while they fit in a cache budget, `u8` past it).
    let key_bytes = match neighbors {
        // `wcsph`'s grid lists hold index keys at every size.
        NeighborMode::Grid if preset == Preset::Wcsph => GridKeys::Index.slot_bytes(),
        NeighborMode::Grid => GridKeys::for_lists(n, lists_of).slot_bytes(),
        NeighborMode::AllPairs => size_of::<u32>(),
    };
    let per_particle =
        FIELD_NAMES.len() * size_of::<f64>() + size_of::<u32>() + lists_of * key_bytes;
    let mut bytes = n64
        .saturating_mul(per_particle as u64)
        .saturating_add(fluid_scratch);
    if neighbors == NeighborMode::Grid {
        let grid_per_particle = 2 * size_of::<u32>() + 2 * size_of::<f64>();
        let bounds = physics.search_bounds(domain);
        let h = physics.search_radius();
        // As `Grid::new` sizes it: floor(extent / h) + 1 cells along each axis plus a ring of
        // empty cells, and one start more than there are cells. Float-to-int casts saturate.
        let cols = (bounds.width() / h) as u64 + 1 + 2;
        let rows = (bounds.height() / h) as u64 + 1 + 2;
        let starts = cols.saturating_mul(rows).saturating_add(1);
        bytes = bytes
            .saturating_add(n64.saturating_mul(grid_per_particle as u64))
            .saturating_add(starts.saturating_mul(size_of::<u32>() as u64))
            .saturating_add(Grid::<u8>::sort_scratch_bytes(n) as u64);
    }
    bytes
}

/// Refuses a run of `n` particles that exceeds [`MAX_PARTICLES`], or whose [`estimate`]
/// exceeds `available` bytes. With `available` unknown (`None`), only the hard limit applies.
pub fn check(
    preset: Preset,
    neighbors: NeighborMode,
    n: usize,
    available: Option<u64>,
) -> Result<(), MemoryError> {
    if n > MAX_PARTICLES {
        return Err(MemoryError::TooMany { n });
    }
    let needs = estimate(preset, neighbors, n);
    match available {
        Some(available) if needs > available => Err(MemoryError::TooLarge {
            n,
            neighbors,
            needs,
            available,
        }),
        _ => Ok(()),
    }
}

/// Hidden, for tests: the bytes of memory to take as available instead of `MemAvailable` in
/// `/proc/meminfo`, so that the refusal of a run too large for the machine can be tested on
/// any machine (e.g. `BENCH_SPH_FAKE_MEM_AVAILABLE=1000000`).
pub const FAKE_MEM_AVAILABLE_VAR: &str = "BENCH_SPH_FAKE_MEM_AVAILABLE";

/// The memory available to a run: [`FAKE_MEM_AVAILABLE_VAR`] if set, else
/// [`available_bytes`].
pub fn available_for_run() -> Option<u64> {
    match std::env::var(FAKE_MEM_AVAILABLE_VAR) {
        Ok(bytes) => bytes.parse().ok(),
        Err(_) => available_bytes(),
    }
}

/// The memory the kernel says can be allocated without swapping (`MemAvailable` in
/// `/proc/meminfo`), bytes; `None` where that cannot be read (not Linux, old kernels).
pub fn available_bytes() -> Option<u64> {
    parse_mem_available(&std::fs::read_to_string("/proc/meminfo").ok()?)
}

/// `MemAvailable: 123 kB` from the text of `/proc/meminfo`, in bytes.
fn parse_mem_available(meminfo: &str) -> Option<u64> {
    let line = meminfo.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let mut words = line.split_whitespace().skip(1);
    let value: u64 = words.next()?.parse().ok()?;
    match words.next() {
        Some("kB") => value.checked_mul(1024),
        None => Some(value),
        Some(_) => None,
    }
}

/// `bytes` in SI units to two significant digits: `230 GB`, `21 GB`, `5.4 GB`, `950 MB`.
pub fn human_bytes(bytes: u64) -> String {
    const UNITS: [(&str, f64); 4] = [("GB", 1e9), ("MB", 1e6), ("kB", 1e3), ("B", 1.0)];
    let b = bytes as f64;
    let (unit, scale) = UNITS
        .into_iter()
        .find(|&(_, scale)| b >= scale)
        .unwrap_or(UNITS[3]);
    let v = b / scale;
    if v >= 100.0 {
        format!("{:.0} {unit}", (v / 10.0).round() * 10.0)
    } else if v >= 10.0 || unit == "B" {
        format!("{v:.0} {unit}")
    } else {
        format!("{v:.1} {unit}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_estimate_is_what_a_simulation_allocates() {
        for preset in Preset::ALL {
            for mode in NeighborMode::ALL {
                for n in [1, 1000, 5000, 70_000, 100_000] {
                    let scene = crate::scene::Scene::dam_break(preset, n, 1).unwrap();
                    let state_bytes: usize = scene
                        .state
                        .fields()
                        .iter()
                        .map(|f| std::mem::size_of_val(*f))
                        .sum();
                    let sim = scene.simulate(mode);
                    let held = (state_bytes + sim.neighbor_heap_bytes()) as u64;
                    assert_eq!(estimate(preset, mode, n), held, "{preset} {mode} {n}");
                }
            }
        }
    }

    #[test]
    fn a_billion_particles_on_the_grid_need_about_170_gb_and_are_refused_on_21() {
        let needs = estimate(Preset::Seed, NeighborMode::Grid, 1_000_000_000);
        assert_eq!(human_bytes(needs), "170 GB");
        // The hard limit comes first; below it the same rule gives the same sentence.
        assert_eq!(
            check(Preset::Seed, NeighborMode::Grid, 1_000_000_000, None),
            Err(MemoryError::TooMany { n: 1_000_000_000 })
        );
        let err = MemoryError::TooLarge {
            n: 1_000_000_000,
            neighbors: NeighborMode::Grid,
            needs,
            available: 21_300_000_000,
        };
        assert_eq!(
            err.to_string(),
            "--n 1000000000 needs about 170 GB of memory (grid search); \
             this machine has 21 GB available"
        );
    }

    #[test]
    fn a_run_that_fits_passes_and_one_that_does_not_is_refused() {
        let n = MAX_PARTICLES;
        let needs = estimate(Preset::Cpp, NeighborMode::AllPairs, n);
        assert!(check(Preset::Cpp, NeighborMode::AllPairs, n, Some(needs)).is_ok());
        assert!(check(Preset::Cpp, NeighborMode::AllPairs, n, None).is_ok());
        let err = check(Preset::Cpp, NeighborMode::AllPairs, n, Some(needs - 1)).unwrap_err();
        assert!(err.to_string().contains("(all-pairs search)"), "{err}");
        assert_eq!(
            check(Preset::Seed, NeighborMode::Grid, usize::MAX, Some(u64::MAX)),
            Err(MemoryError::TooMany { n: usize::MAX })
        );
        assert_eq!(
            estimate(Preset::Seed, NeighborMode::Grid, usize::MAX),
            u64::MAX
        );
    }

    #[test]
    fn mem_available_is_read_in_kilobytes() {
        let text = "MemTotal:       24000000 kB\nMemAvailable:   21000000 kB\n";
        assert_eq!(parse_mem_available(text), Some(21_000_000 * 1024));
        assert_eq!(parse_mem_available("MemTotal: 5 kB\n"), None);
    }

    #[test]
    fn sizes_are_shown_to_two_significant_digits() {
        assert_eq!(human_bytes(21_900_000_000), "22 GB");
        assert_eq!(human_bytes(5_440_000_000), "5.4 GB");
        assert_eq!(human_bytes(950_000_000), "950 MB");
        assert_eq!(human_bytes(12), "12 B");
    }
}
