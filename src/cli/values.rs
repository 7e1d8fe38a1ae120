//! The command line's names for the domain's enums, in one place: the solver's `sph` and the
//! report's `render` know nothing of clap. Each CLI enum carries the help text of its values
//! and maps onto its domain type; an option keeps the domain type, parsed by [`preset`],
//! [`neighbors`], [`order`], [`color`] or [`strategy`] (the strategies' names come from their
//! registry).

use std::ffi::OsStr;

use clap::builder::{EnumValueParser, PossibleValue, TypedValueParser};
use clap::{Arg, ValueEnum};
use sph_strategies::StrategyName;

use crate::models::Preset;
use crate::render::scale::ColorBy;
use crate::results::params::Schedule;
use crate::simd::SimdPath;
use crate::sph::neighbors::{NeighborMode, SumOrder};
use crate::topology::Pin;

/// `--preset`'s values.
#[derive(Debug, Clone, Copy, ValueEnum)]
enum PresetArg {
    /// The seed paper's Haskell program (`schuermannator/sph`), all f64.
    Seed,
    /// The C++ original (`cerrno/mueller-sph` at e0821c49), evaluated in f64.
    Cpp,
    /// Weakly compressible SPH in SI units, validated against Martin & Moyce (1952).
    Wcsph,
}

impl From<PresetArg> for Preset {
    fn from(arg: PresetArg) -> Preset {
        match arg {
            PresetArg::Seed => Preset::Seed,
            PresetArg::Cpp => Preset::Cpp,
            PresetArg::Wcsph => Preset::Wcsph,
        }
    }
}

/// `--neighbors`' values.
#[derive(Debug, Clone, Copy, ValueEnum)]
enum NeighborsArg {
    /// Every particle against every particle, O(N²) per pass: the sources' loops.
    AllPairs,
    /// A uniform cell list with cell size H, rebuilt every step by counting sort: O(N).
    Grid,
}

impl From<NeighborsArg> for NeighborMode {
    fn from(arg: NeighborsArg) -> NeighborMode {
        match arg {
            NeighborsArg::AllPairs => NeighborMode::AllPairs,
            NeighborsArg::Grid => NeighborMode::Grid,
        }
    }
}

/// `--order`'s values.
#[derive(Debug, Clone, Copy, ValueEnum)]
enum OrderArg {
    /// Increasing index, as the sources' loops: the seed's and the C++ program's bits.
    Index,
    /// The grid's cell order: faster, not the sources' bits, the same bits on every strategy.
    Cell,
}

impl From<OrderArg> for SumOrder {
    fn from(arg: OrderArg) -> SumOrder {
        match arg {
            OrderArg::Index => SumOrder::Index,
            OrderArg::Cell => SumOrder::Cell,
        }
    }
}

/// `--simd`'s values.
#[derive(Debug, Clone, Copy, ValueEnum)]
enum SimdArg {
    /// What the compiled target guarantees (SSE2 on x86-64): the reference path.
    Portable,
    /// x86-64 AVX2, 4 lanes of f64.
    Avx2,
    /// x86-64 AVX-512, 8 lanes of f64.
    Avx512,
}

impl From<SimdArg> for SimdPath {
    fn from(arg: SimdArg) -> SimdPath {
        match arg {
            SimdArg::Portable => SimdPath::Portable,
            SimdArg::Avx2 => SimdPath::Avx2,
            SimdArg::Avx512 => SimdPath::Avx512,
        }
    }
}

/// `--pin`'s values.
#[derive(Debug, Clone, Copy, ValueEnum)]
enum PinArg {
    /// The operating system places the threads (the default, as the paper measured).
    None,
    /// Fill the SMT siblings of one physical core before the next core.
    Compact,
    /// One thread per physical core first; SMT siblings only after every core has one.
    Spread,
}

impl From<PinArg> for Pin {
    fn from(arg: PinArg) -> Pin {
        match arg {
            PinArg::None => Pin::None,
            PinArg::Compact => Pin::Compact,
            PinArg::Spread => Pin::Spread,
        }
    }
}

/// `--color`'s values.
#[derive(Debug, Clone, Copy, ValueEnum)]
enum ColorArg {
    /// Speed `|v|`, px/s.
    Speed,
    /// Density ρ (as the solver defines it).
    Density,
}

impl From<ColorArg> for ColorBy {
    fn from(arg: ColorArg) -> ColorBy {
        match arg {
            ColorArg::Speed => ColorBy::Speed,
            ColorArg::Density => ColorBy::Density,
        }
    }
}

/// Parses a [`Preset`] by its command-line name, listing the presets in `--help`.
pub(super) fn preset() -> impl TypedValueParser<Value = Preset> {
    NonEmpty(EnumValueParser::<PresetArg>::new().map(Preset::from))
}

/// Parses a [`NeighborMode`] by its command-line name, listing the modes in `--help`.
pub(super) fn neighbors() -> impl TypedValueParser<Value = NeighborMode> {
    NonEmpty(EnumValueParser::<NeighborsArg>::new().map(NeighborMode::from))
}

/// Parses a [`SimdPath`] by its command-line name, listing the paths in `--help`.
pub(super) fn simd() -> impl TypedValueParser<Value = SimdPath> {
    EnumValueParser::<SimdArg>::new().map(SimdPath::from)
}

/// Parses a [`SumOrder`] by its command-line name, listing the orders in `--help`.
pub(super) fn order() -> impl TypedValueParser<Value = SumOrder> {
    EnumValueParser::<OrderArg>::new().map(SumOrder::from)
}

/// Parses a [`Pin`] by its command-line name, listing the placements in `--help`.
pub(super) fn pin() -> impl TypedValueParser<Value = Pin> {
    NonEmpty(EnumValueParser::<PinArg>::new().map(Pin::from))
}

/// `sweep --schedule`'s values.
#[derive(Debug, Clone, Copy, ValueEnum)]
enum ScheduleArg {
    /// Shuffled rounds: in each, every cell of a group runs once (the default).
    Rounds,
    /// Each cell's trials back to back, cell after cell (the first versions' order).
    Cells,
}

impl From<ScheduleArg> for Schedule {
    fn from(arg: ScheduleArg) -> Schedule {
        match arg {
            ScheduleArg::Rounds => Schedule::Rounds,
            ScheduleArg::Cells => Schedule::Cells,
        }
    }
}

/// Parses `sweep --schedule`.
pub(super) fn schedule() -> impl TypedValueParser<Value = Schedule> {
    EnumValueParser::<ScheduleArg>::new().map(Schedule::from)
}

/// Parses a [`ColorBy`] by its command-line name, listing the quantities in `--help`.
pub(super) fn color() -> impl TypedValueParser<Value = ColorBy> {
    EnumValueParser::<ColorArg>::new().map(ColorBy::from)
}

/// Parses a [`StrategyName`] from the registry, listing [`StrategyName::ALL`] in `--help`; an
/// unknown name is an error that lists the known ones.
pub(super) fn strategy() -> impl TypedValueParser<Value = StrategyName> {
    NonEmpty(StrategyParser)
}

/// A parser of one name that answers an empty one — an empty item of a comma list
/// (`--pin spread,,`) or `--pin ''` — by saying so and listing the names, where clap alone
/// would say that "none was supplied".
#[derive(Debug, Clone, Copy)]
pub(super) struct NonEmpty<P>(P);

impl<P: TypedValueParser> TypedValueParser for NonEmpty<P> {
    type Value = P::Value;

    fn parse_ref(
        &self,
        cmd: &clap::Command,
        arg: Option<&Arg>,
        value: &OsStr,
    ) -> Result<P::Value, clap::Error> {
        if !value.is_empty() {
            return self.0.parse_ref(cmd, arg, value);
        }
        let option = arg
            .and_then(Arg::get_long)
            .map_or_else(|| "an option".to_owned(), |long| format!("--{long}"));
        let names: Vec<String> = self
            .0
            .possible_values()
            .into_iter()
            .flatten()
            .map(|v| v.get_name().to_owned())
            .collect();
        let message = format!(
            "{option} has an empty name (two commas in a row, or one at either end of the \
             list); give one or more of {}, separated by single commas\n",
            names.join(", ")
        );
        Err(clap::Error::raw(clap::error::ErrorKind::InvalidValue, message).with_cmd(cmd))
    }

    fn possible_values(&self) -> Option<Box<dyn Iterator<Item = PossibleValue> + '_>> {
        self.0.possible_values()
    }
}

/// See [`strategy`].
#[derive(Debug, Clone, Copy)]
struct StrategyParser;

impl TypedValueParser for StrategyParser {
    type Value = StrategyName;

    fn parse_ref(
        &self,
        cmd: &clap::Command,
        arg: Option<&Arg>,
        value: &OsStr,
    ) -> Result<StrategyName, clap::Error> {
        let parse = |s: &str| s.parse::<StrategyName>().map_err(|e| e.to_string());
        parse.parse_ref(cmd, arg, value)
    }

    fn possible_values(&self) -> Option<Box<dyn Iterator<Item = PossibleValue> + '_>> {
        Some(Box::new(
            StrategyName::ALL
                .iter()
                .map(|s| PossibleValue::new(s.as_str())),
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde::Serialize;

    /// Each value of `A` as the command line names it, beside its domain value's name in the
    /// CSVs and meta.json.
    fn names<A: ValueEnum + Copy, D: From<A> + Serialize>() -> Vec<(String, String)> {
        A::value_variants()
            .iter()
            .map(|&a| {
                let cli = a.to_possible_value().unwrap().get_name().to_owned();
                let domain = serde_json::to_value(D::from(a)).unwrap();
                (cli, domain.as_str().unwrap().to_owned())
            })
            .collect()
    }

    #[test]
    fn every_command_line_value_maps_to_the_domain_value_of_the_same_name() {
        let all = [
            names::<PresetArg, Preset>(),
            names::<NeighborsArg, NeighborMode>(),
            names::<OrderArg, SumOrder>(),
            names::<ColorArg, ColorBy>(),
            names::<SimdArg, SimdPath>(),
            names::<PinArg, Pin>(),
        ];
        for (cli, domain) in all.iter().flatten() {
            assert_eq!(cli, domain);
        }
    }

    #[test]
    fn every_domain_value_has_a_command_line_value() {
        assert_eq!(PresetArg::value_variants().len(), Preset::ALL.len());
        assert_eq!(
            NeighborsArg::value_variants().len(),
            NeighborMode::ALL.len()
        );
        assert_eq!(OrderArg::value_variants().len(), SumOrder::ALL.len());
        assert_eq!(ColorArg::value_variants().len(), ColorBy::ALL.len());
        assert_eq!(SimdArg::value_variants().len(), SimdPath::ALL.len());
        assert_eq!(PinArg::value_variants().len(), Pin::ALL.len());
    }
}
