//! `bench-sph merge`: one results directory from the shards of a sweep.

use std::path::PathBuf;

use anyhow::Context;
use clap::Args;

/// Options of `merge`.
#[derive(Debug, Clone, Args)]
pub struct MergeArgs {
    /// The shard directories of `bench-sph sweep --shard I/K` (one per shard, any order).
    #[arg(value_name = "SHARD_DIR", required = true)]
    pub dirs: Vec<PathBuf>,
    /// The merged results directory (new or empty, unless --force).
    #[arg(long, value_name = "DIR", required = true)]
    pub out: PathBuf,
    /// Merge even when cells are missing (a shard not given or unfinished, rows left out) or a
    /// shard's seq is unusable (its cells are then merged without a speedup): the merge is
    /// then marked partial, and its report says so.
    #[arg(long)]
    pub allow_partial: bool,
    /// Replace an earlier sweep's or merge's results in --out (the files its record,
    /// bench-sph-files.json, gives to them, and the report drawn there); other files stay
    /// untouched.
    #[arg(long)]
    pub force: bool,
}

/// Runs `merge` and says what it wrote.
pub fn run(args: &MergeArgs) -> anyhow::Result<()> {
    let merged = crate::merge::run(&crate::merge::Request {
        dirs: args.dirs.clone(),
        out: args.out.clone(),
        allow_partial: args.allow_partial,
        force: args.force,
    })?;
    for w in &merged.warnings {
        crate::output::console::warn(&format!("warning: {w}"));
    }
    let dir = merged.dir.display();
    let text = format!(
        "Merged {} of plan {} into {dir}: {} of the plan's {} cells, {} trial rows; every \
         shard's seq rows ({}) in {dir}/references.csv.\nDraw the report with `bench-sph report \
         {dir}`.",
        crate::output::console::plural(args.dirs.len(), "shard", "shards"),
        merged.fingerprint,
        merged.cells.0,
        merged.cells.1,
        merged.trial_rows,
        merged.references,
    );
    crate::output::console::line(&text).with_context(|| {
        format!("cannot write to standard output (the merged files in '{dir}' are written)")
    })
}
