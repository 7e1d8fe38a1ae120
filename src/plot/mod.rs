//! Shared drawing support for every chart and animation: the bundled font.

pub mod font;
