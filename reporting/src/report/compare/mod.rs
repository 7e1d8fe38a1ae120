//! Comparing machines: `bench-sph report` on results directories of different machines.
//!
//! Directories whose `meta.json` machines differ are never pooled: they form **sides**, one
//! per machine ([`sides`]; `--compare` makes every directory a side), and the report becomes
//! a comparison: the machines, then per workload measured on two sides or more each machine's
//! fastest strategy and one chart per strategy with a line per machine ([`plan`], pure), then
//! per side a short summary ([`markdown`], pure). Where `--compare` sets apart directories of
//! the same machine, each pair also gets a reproducibility section ([`reproduce`]): how much of
//! the first the second reproduced. [`crate::report::generate`] draws the charts
//! ([`crate::report::charts::compare`]) and writes the text.
//!
//! A comparison is the ordinary report's machinery with the machine as one more key: each
//! side's groups are ordinary [`GroupView`](crate::report::view::GroupView)s, a machine's
//! fastest strategy is the findings' own [`Verdict`](crate::report::verdict::Verdict), and its
//! charts are ordinary [`ChartPlan`](crate::report::plan::ChartPlan)s drawn and embedded as
//! every other chart. What is the comparison's own: forming sides, matching workloads across
//! them, the machines' table, the wording across machines and the reproducibility section.
//!
//! A cell counts once within a side (the same cell in two directories of one machine is
//! refused, as in a single study); the same cell on two sides is what a comparison compares.
//! Chart files are named `compare-…`, so that they never take the name of a chart of the
//! normal report.

pub mod markdown;
pub mod plan;
pub mod reproduce;
pub mod sides;

pub use sides::SideRule;
