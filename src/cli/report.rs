//! `bench-sph report`: charts and REPORT.md from one or more results directories.

use std::path::PathBuf;

use anyhow::Context;
use clap::Args;

use crate::report::compare::SideRule;

/// Options of `report`.
#[derive(Debug, Clone, Args)]
pub struct ReportArgs {
    /// Results directories of `bench-sph sweep` (each with summary.csv and meta.json); several
    /// of one machine are read as one study (e.g. an all-pairs sweep and a grid sweep);
    /// directories of different machines (CPU model or hardware threads in meta.json) are
    /// compared, never pooled.
    #[arg(value_name = "DIR", required = true)]
    pub dirs: Vec<PathBuf>,
    /// Where to write the charts and REPORT.md [default: the first DIR; required when the
    /// directories are compared, which must not replace one directory's own report].
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// A trace directory of `bench-sph trace` to embed (repeatable). Trace directories under
    /// the results directories or the output directory are found without it.
    #[arg(long, value_name = "DIR")]
    pub trace: Vec<PathBuf>,
    /// Write into an --out directory that holds files bench-sph report did not write (they
    /// stay untouched; only the report's own files are replaced).
    #[arg(long)]
    pub force: bool,
    /// Compare the directories, one side each, even when they ran on the same machine (the
    /// report then warns that their differences are not machine differences).
    #[arg(long)]
    pub compare: bool,
}

/// Runs `report`.
pub fn run(args: &ReportArgs) -> anyhow::Result<()> {
    let out = args.out.clone().unwrap_or_else(|| args.dirs[0].clone());
    let rule = if args.compare {
        SideRule::EachDirectory
    } else {
        SideRule::ByMachine
    };
    let written = crate::report::generate_with(&args.dirs, &out, &args.trace, args.force, rule)?;
    let mut text = format!("Report in {}:", out.display());
    for p in &written {
        text.push_str(&format!("\n  {}", p.display()));
    }
    crate::output::console::line(&text).context("cannot print to standard output")?;
    Ok(())
}
