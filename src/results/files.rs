//! The names of the files in a results directory, and how to recognise the ones bench-sph
//! writes there: the sweep's `trials.csv`, `summary.csv`, `meta.json` and `sweep.lock`, and the
//! report a sweep (or `bench-sph report`) draws beside them.

use std::path::Path;

use crate::output::sniff::{png_size, starts_with};

/// The per-trial file.
pub const TRIALS_FILE: &str = "trials.csv";
/// The per-cell file.
pub const SUMMARY_FILE: &str = "summary.csv";
/// The metadata file.
pub const META_FILE: &str = "meta.json";
/// Every shard's `seq` rows, in a merge of shards (`bench-sph merge`; `summary.csv`'s columns).
pub const REFERENCES_FILE: &str = "references.csv";
/// The sweep's lock file (see `crate::sweep::lock`).
pub const LOCK_FILE: &str = "sweep.lock";

/// Width of every report chart, pixels.
pub const CHART_WIDTH: u32 = 1000;
/// Height of every report chart, pixels.
pub const CHART_HEIGHT: u32 = 650;

/// Width of a trace's `timeline.png` (`trace::timeline::WIDTH`), which a report copies
/// beside its charts, pixels.
pub const TIMELINE_WIDTH: u32 = 1600;

/// The report's file name.
pub const REPORT_FILE: &str = "REPORT.md";

/// How the charts of a comparison of machines begin (`compare-seed-all-pairs-n1000-s100-…`),
/// so that no name of theirs is a chart name of a normal report (those begin with a preset).
pub const COMPARE_CHART_PREFIX: &str = "compare-";

/// Whether a file is one `bench-sph report` writes, by name **and** contents, so that a
/// user's file that merely has a similar name is never replaced or removed: a `REPORT.md`
/// that starts with `# bench-sph report`, a chart (`<preset>-….png` or, comparing machines,
/// `compare-….png`, a PNG of the charts' size) or a copied timeline (`…-timeline.png`, a PNG
/// of the timelines' width). A sweep that draws its report owns these too.
pub fn is_report_file(path: &Path) -> bool {
    use crate::sph::params::Preset;
    let Some(name) = path.file_name().and_then(|n| n.to_str()) else {
        return false;
    };
    if name == REPORT_FILE {
        return starts_with(path, b"# bench-sph report");
    }
    if !name.ends_with(".png") {
        return false;
    }
    if name.ends_with("-timeline.png") {
        return png_size(path).is_some_and(|(w, _)| w == TIMELINE_WIDTH);
    }
    let prefixed = name.starts_with(COMPARE_CHART_PREFIX)
        || Preset::ALL
            .iter()
            .any(|p| name.starts_with(&format!("{}-", p.as_str())));
    prefixed && png_size(path) == Some((CHART_WIDTH, CHART_HEIGHT))
}
