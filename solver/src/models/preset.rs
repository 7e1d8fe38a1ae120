//! The presets: a user's name for a model and its constants (`seed` and `cpp` are Müller's
//! model with each source's constants, `wcsph` the weakly compressible one).

use serde::{Deserialize, Serialize};

use crate::models::mueller::params::{Integrator, Params};

/// Which source program's constants and integration order to reproduce.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Preset {
    /// The seed paper's Haskell program (`schuermannator/sph`), all f64.
    Seed,
    /// The C++ original (`cerrno/mueller-sph` at e0821c49), evaluated in f64.
    Cpp,
    /// Weakly compressible SPH in SI units, validated against Martin & Moyce (1952) (see
    /// [`crate::models::wcsph`]).
    Wcsph,
}

impl Preset {
    /// Every preset, default first.
    pub const ALL: [Preset; 3] = [Preset::Seed, Preset::Cpp, Preset::Wcsph];

    /// The presets of Müller's pixel-unit model, whose constants are a [`Params`].
    pub const MUELLER: [Preset; 2] = [Preset::Seed, Preset::Cpp];

    /// The name used on the command line and in CSV files.
    pub fn as_str(self) -> &'static str {
        match self {
            Preset::Seed => "seed",
            Preset::Cpp => "cpp",
            Preset::Wcsph => "wcsph",
        }
    }

    /// Whether this is one of Müller's pixel-unit presets ([`Preset::MUELLER`]).
    pub fn is_mueller(self) -> bool {
        matches!(self, Preset::Seed | Preset::Cpp)
    }

    /// The constants of a Müller preset.
    ///
    /// # Panics
    /// For [`Preset::Wcsph`], whose constants depend on its resolution
    /// ([`crate::models::wcsph::params::WcParams`]; [`crate::scene::Scene`] builds either).
    pub fn params(self) -> Params {
        match self {
            Preset::Seed => Params::new(Integrator::Seed, 12000.0 * -9.8, 0.0009, -1.0),
            Preset::Cpp => Params::new(Integrator::Cpp, -117600.0, 0.0008, -0.5),
            Preset::Wcsph => panic!("the wcsph preset has no Müller constants"),
        }
    }
}

impl std::fmt::Display for Preset {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::models::mueller::params::Integrator;
    use glam::DVec2;

    // The literals are the constants as printed in the design notes, to 17 digits.
    #[allow(clippy::excessive_precision)]
    #[test]
    fn seed_constants_have_the_bits_the_haskell_program_computes() {
        let p = Preset::Seed.params();
        assert_eq!(p.gravity.y.to_bits(), (-117600.00000000001455f64).to_bits());
        assert_ne!(
            p.gravity.y, -117600.0,
            "12000 * -9.8 is not exactly -117600 in f64"
        );
        assert_eq!(p.poly6, 2.2447474172780788e-11);
        assert_eq!(p.spiky_grad, -8.5377364625159387e-07);
        assert_eq!(p.visc_lap, 8.5377364625159387e-07);
        assert_eq!((p.dt, p.bound_damping, p.hsq), (0.0009, -1.0, 256.0));
    }

    #[test]
    fn cpp_constants_differ_only_in_gravity_time_step_and_damping() {
        let (s, c) = (Preset::Seed.params(), Preset::Cpp.params());
        assert_eq!(c.gravity, DVec2::new(0.0, -117600.0));
        assert_eq!((c.dt, c.bound_damping), (0.0008, -0.5));
        assert_eq!(c.integrator, Integrator::Cpp);
        let same = Params {
            gravity: s.gravity,
            dt: s.dt,
            bound_damping: s.bound_damping,
            integrator: s.integrator,
            ..c
        };
        assert_eq!(same, s);
    }
}
