//! The dam-break layouts of the two presets, and how they grow past their capacity.
//!
//! - `seed`: rows y = 300, 316, … ≤ 876 (37 rows); x = 16, 32, … ≤ 608 (38 columns): up to
//!   1406 particles in a 1200 × 900 domain.
//! - `cpp`: rows y = 16, 32, … < 868 (54 rows); x = 300, 316, … ≤ 600 (19 columns): up to
//!   1026 particles in a 1200 × 900 domain.
//!
//! Particles fill the layout row by row (lowest row first), taking the first N; particle k gets
//! a jitter in [0, 1) added to x, the k-th draw of [`SplitMix64`] seeded with `--seed`.
//!
//! **Growth rule.** For N above the capacity the rows stay and columns are added:
//! `columns = ceil(N / rows)`, and the domain widens by two cell widths (2 H = 32 px) per added
//! column, so the dam keeps about its share of the tank. The domain therefore depends only on
//! (preset, N), and a state dumped with `--dump` loads back with `--init`.

use std::collections::TryReserveError;

use crate::models::Preset;
use crate::scene::splitmix::SplitMix64;
use crate::sph::state::{Domain, State, try_zeros};

/// Width and height of both presets' tank before growth, px (1.5 × an 800 × 600 window).
const BASE_DOMAIN: Domain = Domain {
    width: 1200.0,
    height: 900.0,
};

/// Spacing between particles of the layout, px (the kernel radius H).
const SPACING: f64 = 16.0;

/// Where a preset's dam starts and how many rows and columns it has before growth.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Layout {
    /// x of the first column, px.
    pub x0: f64,
    /// y of the lowest row, px.
    pub y0: f64,
    /// Number of rows (fixed).
    pub rows: usize,
    /// Columns before growth.
    pub base_columns: usize,
}

impl Layout {
    /// The preset's layout.
    ///
    /// # Panics
    /// For [`Preset::Wcsph`], whose scene is [`crate::models::wcsph::scene`].
    pub fn of(preset: Preset) -> Layout {
        match preset {
            Preset::Seed => Layout {
                x0: 16.0,
                y0: 300.0,
                rows: 37,
                base_columns: 38,
            },
            Preset::Cpp => Layout {
                x0: 300.0,
                y0: 16.0,
                rows: 54,
                base_columns: 19,
            },
            Preset::Wcsph => panic!("the wcsph preset's scene is models::wcsph::scene"),
        }
    }

    /// Particles that fit without growing.
    pub fn capacity(&self) -> usize {
        self.rows * self.base_columns
    }

    /// Columns used for `n` particles.
    pub fn columns(&self, n: usize) -> usize {
        if n <= self.capacity() {
            self.base_columns
        } else {
            n.div_ceil(self.rows)
        }
    }
}

/// The tank for `n` particles of `preset` (see the growth rule above).
pub fn domain(preset: Preset, n: usize) -> Domain {
    let layout = Layout::of(preset);
    let added = layout.columns(n) - layout.base_columns;
    Domain {
        width: BASE_DOMAIN.width + 2.0 * SPACING * added as f64,
        height: BASE_DOMAIN.height,
    }
}

/// The initial dam break: `n` particles at rest, x jittered by the seeded generator.
///
/// # Panics
/// If memory runs out (commands call [`try_initial_state`], after [`crate::scene::memory::check`]).
pub fn initial_state(preset: Preset, n: usize, seed: u64) -> State {
    try_initial_state(preset, n, seed)
        .unwrap_or_else(|e| panic!("no memory for {n} particles: {e}"))
}

/// [`initial_state`], with an allocator's refusal as an error instead of an abort.
pub fn try_initial_state(preset: Preset, n: usize, seed: u64) -> Result<State, TryReserveError> {
    let layout = Layout::of(preset);
    let columns = layout.columns(n);
    let mut rng = SplitMix64::new(seed);
    let (mut x, mut y) = (Vec::new(), Vec::new());
    x.try_reserve_exact(n)?;
    y.try_reserve_exact(n)?;
    for k in 0..n {
        let (row, col) = (k / columns, k % columns);
        x.push((layout.x0 + SPACING * col as f64) + rng.next_f64());
        y.push(layout.y0 + SPACING * row as f64);
    }
    State::try_from_kinematics(x, y, try_zeros(n)?, try_zeros(n)?)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_layouts_hold_what_the_sources_generate() {
        // seed: y from 300 while <= 876 (Haskell's range runs to 868 + 8), x from 16 to 608.
        let s = Layout::of(Preset::Seed);
        assert_eq!(s.y0 + SPACING * (s.rows - 1) as f64, 876.0);
        assert_eq!(s.x0 + SPACING * (s.base_columns - 1) as f64, 608.0);
        assert_eq!(s.capacity(), 1406);
        // cpp: y from 16 while < 868, x from 300 while <= 600.
        let c = Layout::of(Preset::Cpp);
        let (last_row, next_row) = (
            c.y0 + SPACING * (c.rows - 1) as f64,
            c.y0 + SPACING * c.rows as f64,
        );
        assert!(last_row < 868.0 && next_row >= 868.0);
        assert_eq!(c.x0 + SPACING * (c.base_columns - 1) as f64, 588.0);
        assert_eq!(c.capacity(), 1026);
    }

    #[test]
    fn particles_fill_rows_from_the_bottom_with_jitter_below_one_pixel() {
        let st = initial_state(Preset::Seed, 40, 7);
        assert_eq!(st.len(), 40);
        for k in 0..40 {
            let (row, col) = (k / 38, k % 38);
            assert_eq!(st.y[k], 300.0 + 16.0 * row as f64);
            let jitter = st.x[k] - (16.0 + 16.0 * col as f64);
            assert!(
                (0.0..1.0).contains(&jitter),
                "particle {k}: jitter {jitter}"
            );
        }
        assert!(st.vx.iter().chain(&st.vy).chain(&st.rho).all(|&v| v == 0.0));
    }

    #[test]
    fn the_same_seed_gives_the_same_state_and_another_seed_does_not() {
        assert_eq!(
            initial_state(Preset::Cpp, 500, 1),
            initial_state(Preset::Cpp, 500, 1)
        );
        assert_ne!(
            initial_state(Preset::Cpp, 500, 1),
            initial_state(Preset::Cpp, 500, 2)
        );
    }

    #[test]
    fn past_capacity_the_dam_adds_columns_and_the_tank_widens() {
        assert_eq!(domain(Preset::Seed, 1406), BASE_DOMAIN);
        let n = 1_000_000;
        let d = domain(Preset::Seed, n);
        let cols = n.div_ceil(37);
        assert_eq!(d.width, 1200.0 + 32.0 * (cols - 38) as f64);
        let st = initial_state(Preset::Seed, n, 1);
        let max_x = st.x.iter().cloned().fold(f64::MIN, f64::max);
        let max_y = st.y.iter().cloned().fold(f64::MIN, f64::max);
        assert!(
            max_x < d.width - 16.0 && max_x < d.width / 2.0 + 16.0,
            "{max_x} in {d:?}"
        );
        assert!(max_y <= 876.0);
    }
}
