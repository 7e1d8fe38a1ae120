//! The one list of strategies. The CLI, the study runner, the CSVs, the plots, the benches and
//! the tests all iterate over [`StrategyName::ALL`]; picking a strategy by name happens once
//! per run, in [`run`].

use std::fmt;
use std::str::FromStr;

use crate::{BuildError, Config, Info, Session, Strategy};

/// Declares every strategy: `Variant => module::Type`. Adding a strategy is one line here
/// (plus its file and `mod` line).
macro_rules! registry {
    ($($variant:ident => $module:ident :: $ty:ident),* $(,)?) => {
        /// A strategy, named as on the command line and in the CSVs.
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
        pub enum StrategyName {
            $(
                #[doc = concat!("See [`crate::", stringify!($module), "`].")]
                $variant,
            )*
        }

        impl StrategyName {
            /// Every strategy, in registry order.
            pub const ALL: &'static [StrategyName] = &[$(StrategyName::$variant),*];

            /// Name, description and how a pass is cut into kernel calls.
            pub fn info(self) -> Info {
                match self {
                    $(StrategyName::$variant => <crate::$module::$ty as Strategy>::INFO,)*
                }
            }
        }

        /// Builds the named strategy for `config` and runs `session` on it. The only place
        /// where a strategy is chosen by name: everything below it is statically dispatched.
        ///
        /// Fails if the strategy cannot be built or cannot start its threads (see
        /// [`Strategy::run`]).
        pub fn run<S: Session>(
            name: StrategyName,
            config: &Config,
            session: S,
        ) -> Result<S::Output, BuildError> {
            match name {
                $(StrategyName::$variant => {
                    <crate::$module::$ty as Strategy>::build(config)?.run(session)
                })*
            }
        }
    };
}

registry! {
    Seq => seq::Seq,
    RayonIter => rayon_iter::RayonIter,
    RayonSpawn => rayon_spawn::RayonSpawn,
    RayonChunks => rayon_chunks::RayonChunks,
    CrossbeamPool => crossbeam_pool::CrossbeamPool,
    StdStatic => std_static::StdStatic,
    Team => team::Team,
    Chili => chili_join::ChiliJoin,
    Paralight => paralight_pool::ParalightPool,
}

impl StrategyName {
    /// The name used on the command line and in CSV files.
    pub fn as_str(self) -> &'static str {
        self.info().name
    }

    /// Every strategy's name, in registry order.
    pub fn names() -> Vec<&'static str> {
        Self::ALL.iter().map(|s| s.as_str()).collect()
    }
}

impl fmt::Display for StrategyName {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

/// A name that is not in the registry.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("unknown strategy '{given}' (known: {known})")]
pub struct UnknownStrategy {
    /// What was asked for.
    pub given: String,
    /// The registry's names, comma-separated.
    pub known: String,
}

impl FromStr for StrategyName {
    type Err = UnknownStrategy;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Self::ALL
            .iter()
            .copied()
            .find(|n| n.as_str() == s)
            .ok_or_else(|| UnknownStrategy {
                given: s.to_owned(),
                known: Self::names().join(", "),
            })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_registered_name_parses_back_to_its_strategy() {
        for &s in StrategyName::ALL {
            assert_eq!(s.as_str().parse::<StrategyName>(), Ok(s));
        }
    }

    #[test]
    fn an_unknown_name_is_an_error_listing_the_known_ones() {
        let err = "turbo".parse::<StrategyName>().unwrap_err();
        assert!(err.to_string().contains("seq"), "{err}");
    }
}
