//! What a particle's colour shows, and the fixed range it is drawn against.
//!
//! The range is decided once per animation, so the same colour means the same value in every
//! frame; the model gives it (`Model::speed_range` and `density_range`, in each model's
//! `model.rs`), from its constants and the initial state. Müller's presets (pixel units):
//! - **speed** `|v|`, px/s, from 0 to `√(2·|g|·(y_top − EPS))`, the speed of a particle falling
//!   freely from the top of the initial dam to the floor;
//! - **density** ρ, from `ρ_self = MASS·POLY6·HSQ³` (a particle with no neighbours: its own
//!   contribution) to `4·ρ_self`. Densities are computed by a step, so frame 0 (the initial
//!   state, before any step) shows every particle at the bottom of the scale.
//!
//! `wcsph` (SI units), the same for every resolution, so that renders compare:
//! - **speed** `|v|`, m/s, from 0 to `√(2·g·2a)` ≈ 6.26 m/s, the speed of a fall from the top
//!   of the 2a-high column to the floor (also c0 / 10);
//! - **density** ρ, kg/m³, from ρ0 to 1.01 ρ0: Tait's stiffness keeps it within about 1 %
//!   (the hydrostatic density at the foot of the column is 1.005 ρ0).
//!
//! Values outside the range take the colour of its nearer end.

use serde::Serialize;

use sph_solver::models::Physics;
use sph_solver::solver::model::Units;
use sph_solver::sph::state::State;

/// The quantity a particle's colour shows.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum ColorBy {
    /// Speed `|v|`: px/s for Müller's presets, m/s for `wcsph`.
    Speed,
    /// Density ρ (as the solver defines it).
    Density,
}

impl ColorBy {
    /// Every quantity, default first.
    pub const ALL: [ColorBy; 2] = [ColorBy::Speed, ColorBy::Density];
}

/// A quantity and the range of it that spans the colour map.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Scale {
    /// The quantity.
    pub by: ColorBy,
    /// The value drawn in the lowest colour.
    pub lo: f64,
    /// The value drawn in the highest colour (greater than `lo`).
    pub hi: f64,
    /// The units of the values: Müller's pixels or SI.
    pub units: Units,
}

impl Scale {
    /// The range for `by` in an animation of `physics` that starts from `initial`: the
    /// model's (see the module docs).
    pub fn new(by: ColorBy, physics: &Physics, initial: &State) -> Scale {
        let (lo, hi) = match by {
            ColorBy::Speed => physics.speed_range(initial),
            ColorBy::Density => physics.density_range(),
        };
        // A range can be empty (a Müller dam lying on the floor has no fall height): keep it
        // non-empty.
        let hi = if hi > lo { hi } else { lo + 1.0 };
        Scale {
            by,
            lo,
            hi,
            units: physics.units(),
        }
    }

    /// Particle `i`'s value of the quantity.
    pub fn value(&self, state: &State, i: usize) -> f64 {
        match self.by {
            ColorBy::Speed => state.velocity(i).length(),
            ColorBy::Density => state.rho[i],
        }
    }

    /// Where `value` lies in the range: 0 at `lo`, 1 at `hi`, unclamped.
    pub fn fraction(&self, value: f64) -> f64 {
        (value - self.lo) / (self.hi - self.lo)
    }

    /// The legend's title: the quantity and its unit.
    pub fn title(&self) -> &'static str {
        match (self.units, self.by) {
            (Units::Pixels, ColorBy::Speed) => "speed, px/s",
            (Units::Pixels, ColorBy::Density) => "density",
            (Units::Si, ColorBy::Speed) => "speed, m/s",
            (Units::Si, ColorBy::Density) => "density, kg/m³",
        }
    }

    /// A bound of the range as the legend writes it.
    pub fn label(&self, value: f64) -> String {
        match (self.units, self.by) {
            (Units::Pixels, ColorBy::Speed) => format!("{value:.0}"),
            (Units::Pixels, ColorBy::Density) => format!("{value:.3}"),
            (Units::Si, ColorBy::Speed) => format!("{value:.1}"),
            (Units::Si, ColorBy::Density) => format!("{value:.0}"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use sph_solver::models::Preset;
    use sph_solver::models::mueller::scene;
    use sph_solver::models::wcsph::params::WcParams;

    #[test]
    fn the_speed_range_is_the_free_fall_speed_from_the_top_of_the_dam() {
        let params = Preset::Seed.params();
        let state = scene::initial_state(Preset::Seed, 1000, 1);
        let scale = Scale::new(ColorBy::Speed, &params.into(), &state);
        assert_eq!(scale.lo, 0.0);
        // 1000 particles fill 27 rows of 38, so the top row is y = 300 + 16·26; EPS = 16.
        let top: f64 = 300.0 + 16.0 * 26.0;
        let expected = (2.0 * 117_600.0 * (top - 16.0)).sqrt();
        assert!(
            (scale.hi - expected).abs() < 1e-9,
            "{} vs {expected}",
            scale.hi
        );
    }

    #[test]
    fn a_lone_particle_is_at_the_bottom_of_the_density_range() {
        let params = Preset::Cpp.params();
        let scale = Scale::new(ColorBy::Density, &params.into(), &State::default());
        assert!((scale.lo - 315.0 / (std::f64::consts::PI * 16f64.powi(3))).abs() < 1e-12);
        assert_eq!(scale.fraction(scale.lo), 0.0);
        assert_eq!(scale.fraction(scale.hi), 1.0);
    }

    #[test]
    fn a_dam_on_the_floor_still_has_a_non_empty_speed_range() {
        let params = Preset::Seed.params();
        let state = State::from_kinematics(vec![100.0], vec![16.0], vec![0.0], vec![0.0]);
        let scale = Scale::new(ColorBy::Speed, &params.into(), &state);
        assert!(scale.hi > scale.lo);
    }

    #[test]
    fn wcsph_speeds_span_the_free_fall_from_the_column_top_in_metres_per_second() {
        for r in [8, 40] {
            let physics = Physics::from(WcParams::new(r, 0));
            let scale = Scale::new(ColorBy::Speed, &physics, &State::default());
            assert_eq!(scale.lo, 0.0);
            assert!(
                (scale.hi - (2.0 * 9.81 * 2.0f64).sqrt()).abs() < 1e-12,
                "{}",
                scale.hi
            );
            assert_eq!(scale.title(), "speed, m/s");
            assert_eq!(
                (scale.label(scale.lo), scale.label(scale.hi)),
                ("0.0".into(), "6.3".into())
            );
        }
        let density = Scale::new(
            ColorBy::Density,
            &WcParams::new(8, 0).into(),
            &State::default(),
        );
        assert_eq!(density.title(), "density, kg/m³");
        assert_eq!(
            (density.label(density.lo), density.label(density.hi)),
            ("1000".into(), "1010".into())
        );
    }
}
