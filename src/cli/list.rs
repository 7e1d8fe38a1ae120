//! `bench-sph list`: every strategy in the registry, one per line.

use std::io::Write;

use anyhow::Context;

use sph_strategies::StrategyName;

/// Writes one line per strategy: its name, then its description.
pub fn run(out: &mut impl Write) -> anyhow::Result<()> {
    let width = StrategyName::ALL
        .iter()
        .map(|s| s.as_str().len())
        .max()
        .unwrap_or(0);
    for s in StrategyName::ALL {
        let info = s.info();
        writeln!(out, "{:width$}  {}", info.name, info.description)
            .context("cannot write to standard output")?;
    }
    out.flush().context("cannot write to standard output")
}
