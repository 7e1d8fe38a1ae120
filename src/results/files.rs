//! The names of the files in a results directory, and how to recognise the ones bench-sph
//! writes there: the sweep's `trials.csv`, `summary.csv`, `meta.json` and `sweep.lock`, and the
//! report a sweep (or `bench-sph report`) draws beside them.

use std::path::Path;

/// The per-trial file.
pub const TRIALS_FILE: &str = "trials.csv";
/// The per-cell file.
pub const SUMMARY_FILE: &str = "summary.csv";
/// The metadata file.
pub const META_FILE: &str = "meta.json";
/// The sweep's lock file (see `crate::sweep::lock`).
pub const LOCK_FILE: &str = "sweep.lock";

/// Width of every report chart, pixels.
pub const CHART_WIDTH: u32 = 1000;
/// Height of every report chart, pixels.
pub const CHART_HEIGHT: u32 = 650;

/// The report's file name.
pub const REPORT_FILE: &str = "REPORT.md";

/// Whether a file is one `bench-sph report` writes, by name **and** contents, so that a
/// user's file that merely has a similar name is never replaced or removed: a `REPORT.md`
/// that starts with `# bench-sph report`, a chart (`<preset>-….png`, a PNG of the charts'
/// size) or a copied timeline (`…-timeline.png`, a PNG of the timelines' width). A sweep
/// that draws its report owns these too.
pub fn is_report_file(path: &Path) -> bool {
    use crate::sph::params::Preset;
    let Some(name) = path.file_name().and_then(|n| n.to_str()) else {
        return false;
    };
    if name == REPORT_FILE {
        return crate::trace::files::starts_with(path, b"# bench-sph report");
    }
    if !name.ends_with(".png") {
        return false;
    }
    if name.ends_with("-timeline.png") {
        return png_size(path).is_some_and(|(w, _)| w == crate::trace::timeline::WIDTH);
    }
    Preset::ALL
        .iter()
        .any(|p| name.starts_with(&format!("{}-", p.as_str())))
        && png_size(path) == Some((CHART_WIDTH, CHART_HEIGHT))
}

/// Width and height from a PNG file's header, if it is one.
fn png_size(path: &Path) -> Option<(u32, u32)> {
    use std::io::Read;
    let mut head = [0u8; 24];
    std::fs::File::open(path).ok()?.read_exact(&mut head).ok()?;
    if head[..8] != crate::trace::files::PNG_SIGNATURE || &head[12..16] != b"IHDR" {
        return None;
    }
    let word = |i: usize| u32::from_be_bytes([head[i], head[i + 1], head[i + 2], head[i + 3]]);
    Some((word(16), word(20)))
}
