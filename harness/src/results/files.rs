//! The names of the files in a results directory: the sweep's `trials.csv`, `summary.csv` and
//! `meta.json`, a merge's `references.csv`, and the report a sweep (or `bench-sph report`)
//! draws beside them. Which of them bench-sph wrote is the directory's record
//! ([`crate::output::record`]), never a guess from these names.

/// The per-trial file.
pub const TRIALS_FILE: &str = "trials.csv";
/// The per-cell file.
pub const SUMMARY_FILE: &str = "summary.csv";
/// The metadata file.
pub const META_FILE: &str = "meta.json";
/// Every shard's `seq` rows, in a merge of shards (`bench-sph merge`; `summary.csv`'s columns).
pub const REFERENCES_FILE: &str = "references.csv";
/// What a pass costs each strategy at each core count (`sweep --pass-cost`;
/// [`crate::run::pass_cost::CostRow`]).
pub const PASS_COST_FILE: &str = "pass-cost.csv";
/// The OpenMP anchor's runs (`sweep --anchor`; [`super::anchor::AnchorRun`]).
pub const ANCHOR_FILE: &str = "anchor.csv";
/// The report's file name.
pub const REPORT_FILE: &str = "REPORT.md";

/// How the charts of a comparison of machines begin (`compare-seed-all-pairs-n1000-s100-…`),
/// so that no name of theirs is a chart name of a normal report (those begin with a preset).
pub const COMPARE_CHART_PREFIX: &str = "compare-";
