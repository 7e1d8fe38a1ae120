//! Drawing outside the report's charts: the bundled font every chart and animation uses, the
//! trace's timeline (`bench-sph trace`) and the validation chart (`bench-sph validate`). The
//! harness that measures (`trace`, `validate`) draws nothing itself.

pub mod font;
pub mod timeline;
pub mod validation;
