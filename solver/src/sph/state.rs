//! The particle state, one array per field (struct of arrays).

use std::collections::TryReserveError;

use glam::DVec2;

/// The simulation domain: walls at x = 0, x = `width`, y = 0, y = `height` (px).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Domain {
    /// Distance between the left and right walls, px.
    pub width: f64,
    /// Distance between the floor and the ceiling, px.
    pub height: f64,
}

/// Every particle's fields, index `i` in each array being particle `i`.
///
/// `fx, fy, rho, p` hold the values computed during the most recent step (zero before the
/// first). A pass writes some arrays and only reads the others, so passes can run in parallel
/// over particles without copying.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct State {
    /// Position x, px.
    pub x: Vec<f64>,
    /// Position y, px.
    pub y: Vec<f64>,
    /// Velocity x, px/s.
    pub vx: Vec<f64>,
    /// Velocity y, px/s.
    pub vy: Vec<f64>,
    /// Force x (as the sources define it: pressure + viscosity + gravity · rho).
    pub fx: Vec<f64>,
    /// Force y.
    pub fy: Vec<f64>,
    /// Density.
    pub rho: Vec<f64>,
    /// Pressure `GAS_CONST · (rho − REST_DENS)`.
    pub p: Vec<f64>,
}

/// The names of [`State`]'s fields, in dump-column order.
pub const FIELD_NAMES: [&str; 8] = ["x", "y", "vx", "vy", "fx", "fy", "rho", "p"];

impl State {
    /// A state with the given positions and velocities; force, density and pressure zero.
    ///
    /// # Panics
    /// If the four arrays differ in length, or memory runs out.
    pub fn from_kinematics(x: Vec<f64>, y: Vec<f64>, vx: Vec<f64>, vy: Vec<f64>) -> Self {
        let n = x.len();
        Self::try_from_kinematics(x, y, vx, vy)
            .unwrap_or_else(|e| panic!("no memory for {n} particles: {e}"))
    }

    /// [`State::from_kinematics`], but an allocator's refusal is an error instead of an abort
    /// (the commands use this; [`crate::scene::memory`] checks the size first).
    ///
    /// # Panics
    /// If the four arrays differ in length.
    pub fn try_from_kinematics(
        x: Vec<f64>,
        y: Vec<f64>,
        vx: Vec<f64>,
        vy: Vec<f64>,
    ) -> Result<Self, TryReserveError> {
        let n = x.len();
        assert!(
            y.len() == n && vx.len() == n && vy.len() == n,
            "field lengths differ"
        );
        Ok(State {
            x,
            y,
            vx,
            vy,
            fx: try_zeros(n)?,
            fy: try_zeros(n)?,
            rho: try_zeros(n)?,
            p: try_zeros(n)?,
        })
    }

    /// Number of particles.
    pub fn len(&self) -> usize {
        self.x.len()
    }

    /// Whether there are no particles.
    pub fn is_empty(&self) -> bool {
        self.x.is_empty()
    }

    /// Particle `i`'s velocity.
    pub fn velocity(&self, i: usize) -> DVec2 {
        DVec2::new(self.vx[i], self.vy[i])
    }

    /// The fields in [`FIELD_NAMES`] order.
    pub fn fields(&self) -> [&[f64]; 8] {
        [
            &self.x, &self.y, &self.vx, &self.vy, &self.fx, &self.fy, &self.rho, &self.p,
        ]
    }

    /// Whether every velocity component is finite (a quick check; see the solver's
    /// divergence guard).
    pub fn velocities_finite(&self) -> bool {
        first_non_finite(&self.vx).is_none() && first_non_finite(&self.vy).is_none()
    }

    /// Whether every velocity component, density and pressure of the particles in `range` is
    /// finite: the solver's divergence guard, one branch-free pass over the four fields
    /// (inlined, so that it runs in the caller's lanes).
    #[inline(always)]
    pub fn guarded_fields_finite(&self, range: std::ops::Range<usize>) -> bool {
        let (vx, vy) = (&self.vx[range.clone()], &self.vy[range.clone()]);
        let (rho, p) = (&self.rho[range.clone()], &self.p[range]);
        let len = vx.len();
        let (vy, rho, p) = (&vy[..len], &rho[..len], &p[..len]);
        (0..len).fold(true, |ok, k| {
            ok & vx[k].is_finite() & vy[k].is_finite() & rho[k].is_finite() & p[k].is_finite()
        })
    }

    /// The first non-finite value, as (field name, particle index), scanning field by field.
    pub fn first_non_finite(&self) -> Option<(&'static str, usize)> {
        FIELD_NAMES
            .iter()
            .zip(self.fields())
            .find_map(|(name, values)| first_non_finite(values).map(|i| (*name, i)))
    }
}

/// `n` zeros, or the allocator's refusal as an error (where `vec![0.0; n]` would abort).
pub fn try_zeros(n: usize) -> Result<Vec<f64>, TryReserveError> {
    let mut v = Vec::new();
    v.try_reserve_exact(n)?;
    v.resize(n, 0.0);
    Ok(v)
}

/// Index of the first NaN or infinity in `values`. Blocks are checked without branching
/// (so the common all-finite case vectorises) and only a failing block is searched.
fn first_non_finite(values: &[f64]) -> Option<usize> {
    const BLOCK: usize = 64;
    values.chunks(BLOCK).enumerate().find_map(|(b, block)| {
        let all_finite = block.iter().fold(true, |ok, v| ok & v.is_finite());
        if all_finite {
            None
        } else {
            block
                .iter()
                .position(|v| !v.is_finite())
                .map(|k| b * BLOCK + k)
        }
    })
}

/// Read-only fields of every particle, as the passes that sum over neighbours see them.
#[derive(Debug, Clone, Copy)]
pub struct Fields<'a> {
    /// Positions.
    pub pos: Positions<'a>,
    /// Velocity x of every particle.
    pub vx: &'a [f64],
    /// Velocity y of every particle.
    pub vy: &'a [f64],
    /// Density of every particle.
    pub rho: &'a [f64],
    /// Pressure of every particle.
    pub p: &'a [f64],
}

impl<'a> Fields<'a> {
    /// The fields of these arrays (one entry per particle each).
    pub fn new(
        (x, y): (&'a [f64], &'a [f64]),
        (vx, vy): (&'a [f64], &'a [f64]),
        rho: &'a [f64],
        p: &'a [f64],
    ) -> Fields<'a> {
        Fields {
            pos: Positions { x, y },
            vx,
            vy,
            rho,
            p,
        }
    }

    /// The same fields of particles `range` only.
    ///
    /// # Panics
    /// If `range` reaches past an array.
    pub fn of_range(&self, range: std::ops::Range<usize>) -> Fields<'a> {
        let cut = |a: &'a [f64]| &a[range.clone()];
        Fields::new(
            (cut(self.pos.x), cut(self.pos.y)),
            (cut(self.vx), cut(self.vy)),
            cut(self.rho),
            cut(self.p),
        )
    }

    /// The same fields, each cut to the number of particles (the positions' length): in a
    /// loop that reads all six at one index, a single bounds check then covers them.
    ///
    /// # Panics
    /// If an array is shorter than the positions (fields of fluid particles only, as
    /// `wcsph`'s, are not for this).
    #[inline(always)]
    pub fn to_common_length(&self) -> Fields<'a> {
        let n = self.pos.x.len();
        Fields::new(
            (&self.pos.x[..n], &self.pos.y[..n]),
            (&self.vx[..n], &self.vy[..n]),
            &self.rho[..n],
            &self.p[..n],
        )
    }
}

/// Read-only positions, as the neighbour searches and passes see them.
#[derive(Debug, Clone, Copy)]
pub struct Positions<'a> {
    /// x of every particle, px.
    pub x: &'a [f64],
    /// y of every particle, px.
    pub y: &'a [f64],
}

impl Positions<'_> {
    /// Particle `i`'s position.
    #[inline]
    pub fn at(&self, i: usize) -> DVec2 {
        DVec2::new(self.x[i], self.y[i])
    }

    /// Number of particles.
    pub fn len(&self) -> usize {
        self.x.len()
    }

    /// Whether there are no particles.
    pub fn is_empty(&self) -> bool {
        self.x.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_divergence_guard_finds_any_non_finite_velocity_density_or_pressure_in_its_range() {
        let n = 37;
        let state =
            || State::from_kinematics(vec![1.0; n], vec![2.0; n], vec![3.0; n], vec![4.0; n]);
        assert!(state().guarded_fields_finite(0..n));
        for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            for k in [0, 8, 17, n - 1] {
                for field in 0..4 {
                    let mut s = state();
                    [&mut s.vx, &mut s.vy, &mut s.rho, &mut s.p][field][k] = bad;
                    assert!(
                        !s.guarded_fields_finite(0..n),
                        "{bad} in field {field} at {k}"
                    );
                    assert!(!s.guarded_fields_finite(k..k + 1));
                    assert!(s.guarded_fields_finite(0..k), "before it");
                    assert!(s.guarded_fields_finite(k + 1..n), "after it");
                }
                // Positions and forces are not guarded: a non-finite one shows in the
                // velocities in the same step (see the solver's divergence guard).
                let mut s = state();
                (s.x[k], s.fy[k]) = (bad, bad);
                assert!(s.guarded_fields_finite(0..n));
            }
        }
    }

    #[test]
    fn fields_of_a_range_are_those_particles_of_every_array() {
        let a: Vec<f64> = (0..10).map(f64::from).collect();
        let b: Vec<f64> = a.iter().map(|v| 10.0 * v).collect();
        let all = Fields::new((&a, &b), (&b, &a), &a, &b);
        let some = all.of_range(3..6);
        assert_eq!((some.pos.x, some.pos.y), (&a[3..6], &b[3..6]));
        assert_eq!(
            (some.vx, some.vy, some.rho, some.p),
            (&b[3..6], &a[3..6], &a[3..6], &b[3..6])
        );
        assert!(all.of_range(10..10).pos.is_empty());
    }
}
