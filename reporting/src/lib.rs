//! The report and all drawing of bench-sph: what turns the harness's results into words and
//! pictures.
//!
//! - [`report`]: charts and REPORT.md from results directories (`bench-sph report`);
//! - [`plot`]: the bundled font, and the charts drawn outside a report (a trace's timeline,
//!   the validation chart);
//! - [`render`]: animations of the dam break (GIF or PNG frames);
//! - `viewer` (cargo feature `viewer`): the same, live in a window.

pub mod plot;
pub mod render;
pub mod report;
#[cfg(feature = "viewer")]
pub mod viewer;
