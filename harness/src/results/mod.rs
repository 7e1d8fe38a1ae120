//! The results directory's schema, below both the sweep that writes it and the report that
//! reads it: file names ([`files`]), the cell key ([`key`]), the rows and columns of
//! `trials.csv` and `summary.csv` ([`rows`]), `meta.json` ([`meta`]) with the sweep's
//! parameters ([`params`]) written by name ([`names`]), the statistics of a cell ([`stats`])
//! and their intervals ([`intervals`]), a cell's summary row from its trial rows
//! ([`summarize`]), the checks a cell read back must pass ([`validate`]), writing the two CSVs
//! ([`export`]), the lenient reading of whole directories ([`load`]), and opening a directory
//! to write results into ([`dir`]: new or empty, or an earlier sweep's with `--force`).
//!
//! A results directory holds:
//! - `trials.csv`: one row per timed run (columns [`rows::TRIAL_COLUMNS`]), with its phase,
//!   round and place in the round;
//! - `summary.csv`: one row per cell and phase (columns [`rows::SUMMARY_COLUMNS`]): mean,
//!   sample stddev, min, median, max of the wall seconds, mean CPU seconds, speedup over the
//!   group's `seq` (paired by round), efficiency = speedup / cores, outliers
//!   (|t − median| > 3 MAD), oversubscribed, the common checksum, status and reason;
//! - `meta.json`: machine, build, times, command lines and every parameter;
//! - in a merge of shards, `references.csv`: every shard's `seq` rows;
//! - the report drawn from it (`REPORT.md`, charts), and bench-sph's bookkeeping: the record
//!   of the files it wrote there (`bench-sph-files.json`, [`crate::output::record`]) and the
//!   lock file (`bench-sph.lock`, [`crate::output::lock`]).

pub mod anchor;
pub mod dir;
pub mod export;
pub mod files;
#[cfg(any(test, feature = "testing"))]
pub mod fixtures;
pub mod intervals;
pub mod key;
pub mod load;
pub mod meta;
pub mod names;
pub mod params;
pub mod rows;
#[cfg(test)]
mod rows_tests;
pub mod shard;
pub mod stats;
pub mod summarize;
pub mod validate;

pub use files::{
    ANCHOR_FILE, META_FILE, PASS_COST_FILE, REFERENCES_FILE, REPORT_FILE, SUMMARY_FILE, TRIALS_FILE,
};
