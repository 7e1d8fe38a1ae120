//! Names as written in `meta.json` and the CSVs: the same strings as on the command line, for
//! strategies, presets and neighbour searches.

use sph_strategies::StrategyName;

use sph_solver::models::Preset;
use sph_solver::sph::neighbors::NeighborMode;

/// A type written by name in `meta.json` (the same name as on the command line and in CSVs).
pub trait Named: Sized + Copy + 'static {
    /// The name.
    fn name(self) -> &'static str;
    /// Every value, so a name can be looked up.
    fn all() -> &'static [Self];
}

impl Named for StrategyName {
    fn name(self) -> &'static str {
        self.as_str()
    }
    fn all() -> &'static [Self] {
        StrategyName::ALL
    }
}

impl Named for Preset {
    fn name(self) -> &'static str {
        self.as_str()
    }
    fn all() -> &'static [Self] {
        &Preset::ALL
    }
}

impl Named for NeighborMode {
    fn name(self) -> &'static str {
        self.as_str()
    }
    fn all() -> &'static [Self] {
        &NeighborMode::ALL
    }
}

/// Looks a name up among `T::all()`.
pub fn by_name<T: Named>(name: &str) -> Option<T> {
    T::all().iter().copied().find(|v| v.name() == name)
}

/// Looks `name` up among `T::all()`, or a serde error that lists the known names.
fn lookup<T: Named, E: serde::de::Error>(name: &str) -> Result<T, E> {
    by_name(name).ok_or_else(|| {
        let known: Vec<&str> = T::all().iter().map(|v| v.name()).collect();
        E::custom(format!(
            "unknown name '{name}' (known: {})",
            known.join(", ")
        ))
    })
}

/// Serde for one [`Named`] value as its name (the key columns of the results CSVs).
pub mod name {
    use serde::{Deserialize, Deserializer, Serializer};

    use super::{Named, lookup};

    /// Writes the value's name.
    pub fn serialize<T: Named, S: Serializer>(value: &T, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(value.name())
    }

    /// Reads a name; an unknown one is an error.
    pub fn deserialize<'de, T: Named, D: Deserializer<'de>>(d: D) -> Result<T, D::Error> {
        lookup(&String::deserialize(d)?)
    }
}

/// Serde for a list of [`Named`] values as a list of their names.
pub(super) mod name_list {
    use serde::{Deserialize, Deserializer, Serializer};

    use super::{Named, lookup};

    /// Writes the values' names.
    pub fn serialize<T: Named, S: Serializer>(values: &[T], s: S) -> Result<S::Ok, S::Error> {
        s.collect_seq(values.iter().map(|v| v.name()))
    }

    /// Reads names; an unknown one is an error.
    pub fn deserialize<'de, T: Named, D: Deserializer<'de>>(d: D) -> Result<Vec<T>, D::Error> {
        Vec::<String>::deserialize(d)?
            .iter()
            .map(|name| lookup(name))
            .collect()
    }
}
