//! `bench-sph report`: charts and REPORT.md from one or more results directories.

use std::path::PathBuf;

use clap::Args;

/// Options of `report`.
#[derive(Debug, Clone, Args)]
pub struct ReportArgs {
    /// Results directories of `bench-sph sweep` (each with summary.csv and meta.json); several
    /// are read as one study (e.g. an all-pairs sweep and a grid sweep).
    #[arg(value_name = "DIR", required = true)]
    pub dirs: Vec<PathBuf>,
    /// Where to write the charts and REPORT.md [default: the first DIR].
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// A trace directory of `bench-sph trace` to embed (repeatable). Trace directories under
    /// the results directories or the output directory are found without it.
    #[arg(long, value_name = "DIR")]
    pub trace: Vec<PathBuf>,
}

/// Runs `report`.
pub fn run(args: &ReportArgs) -> anyhow::Result<()> {
    let out = args.out.clone().unwrap_or_else(|| args.dirs[0].clone());
    let written = crate::report::generate(&args.dirs, &out, &args.trace)?;
    println!("Report in {}:", out.display());
    for p in &written {
        println!("  {}", p.display());
    }
    Ok(())
}
