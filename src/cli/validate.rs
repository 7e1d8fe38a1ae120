//! `bench-sph validate`: the `wcsph` dam break against Martin & Moyce (1952); writes
//! surge_front.csv, column_height.csv and validation.png into a claimed directory (each file
//! whole or not at all), prints the comparison, and fails when a verdict fails.

use std::path::PathBuf;

use anyhow::Context;
use clap::Args;

use crate::output::atomic::AtomicFile;
use crate::output::claim::{self, Claimed, Owner};
use crate::output::console;
use crate::output::record::Command;
use crate::plot::validation as chart;
use crate::validate::export::{self, COLUMN_HEIGHT_CSV, SURGE_FRONT_CSV, VALIDATION_PNG};
use crate::validate::{self, Validation, summary};

/// Options of `validate`.
#[derive(Debug, Clone, Args)]
pub struct ValidateArgs {
    /// Particles across the water column's width a (4..=400; 2R² fluid particles).
    #[arg(long, value_name = "R", default_value_t = validate::DEFAULT_RESOLUTION, value_parser = super::resolution)]
    pub resolution: usize,
    /// Output directory (created if missing): surge_front.csv, column_height.csv,
    /// validation.png.
    #[arg(long, value_name = "DIR", default_value = "validation")]
    pub out: PathBuf,
    /// Write into an --out directory that holds files validate did not write, leaving them as
    /// they are (only validate's own files are replaced).
    #[arg(long)]
    pub force: bool,
    /// Print one JSON object instead of text.
    #[arg(long)]
    pub json: bool,
    /// How the passes run: strategy, worker threads, chunks.
    #[command(flatten)]
    pub parallel: super::parallel::ParallelArgs,
}

/// Runs `validate`: claims `--out` before anything runs, then runs, writes the three files
/// (renamed into place only once all three are complete), prints, and returns an error naming
/// the failed verdicts, if any.
pub fn run(args: &ValidateArgs) -> anyhow::Result<()> {
    // Claimed (and locked) before anything runs, and held until the files are written.
    let (mut claimed, paths) = claim_out(args)?;
    let config = args.parallel.config()?;
    let v = validate::validate(args.resolution, args.parallel.strategy, &config)?;
    claimed.record(&FILES)?;
    write_files(&paths, &v)?;
    claimed.remove_stale(&paths)?;

    if args.json {
        let text = serde_json::to_string(&summary::Json::of(&v))?;
        say(&text, &claimed)?;
    } else {
        let mut lines = summary::lines(&v);
        lines.push(format!(
            "wrote {}",
            paths
                .iter()
                .map(|p| p.display().to_string())
                .collect::<Vec<_>>()
                .join(", ")
        ));
        for line in &lines {
            say(line, &claimed)?;
        }
    }
    let failed = v.outcome.failed();
    if !failed.is_empty() {
        let names: Vec<&str> = failed.iter().map(|f| f.check.describe()).collect();
        anyhow::bail!(
            "validation failed: {} (the files in '{}' are written)",
            names.join("; "),
            claimed.dir().display()
        );
    }
    Ok(())
}

/// The files validate writes, in order.
const FILES: [&str; 3] = [SURGE_FRONT_CSV, COLUMN_HEIGHT_CSV, VALIDATION_PNG];

/// Claims `--out` for validate and checks that its three files may be written there.
fn claim_out(args: &ValidateArgs) -> anyhow::Result<(Claimed, [PathBuf; 3])> {
    let owner = Owner {
        command: Command::Validate,
        option: "--out",
        replaces: &[],
        tolerates: &[],
        tolerates_unrecorded: &claim::nothing,
        writes: &FILES,
    };
    let claimed = claim::claim(&args.out, &owner, args.force)?;
    let path = |i: usize| claimed.check_writable(FILES[i]);
    let paths = [path(0)?, path(1)?, path(2)?];
    Ok((claimed, paths))
}

/// Writes the three files, each to a temporary name, and renames them into place only once
/// all three are complete: an error leaves the earlier files as they were.
fn write_files(paths: &[PathBuf; 3], v: &Validation) -> anyhow::Result<()> {
    let [front_csv, column_csv, png] = paths;
    let mut out = AtomicFile::create(front_csv)?;
    export::write_surge_front(&v.samples, &v.scales, &mut out)
        .with_context(|| format!("cannot write '{}'", front_csv.display()))?;
    let mut written = vec![out];

    let mut out = AtomicFile::create(column_csv)?;
    export::write_column_height(&v.samples, &v.scales, &mut out)
        .with_context(|| format!("cannot write '{}'", column_csv.display()))?;
    written.push(out);

    let mut out = AtomicFile::create(png)?;
    let plan = chart::plan(&v.experiment, &v.front, &v.column, v.resolution);
    chart::write_png(&plan, &mut out)
        .with_context(|| format!("cannot write '{}'", png.display()))?;
    written.push(out);

    written.into_iter().try_for_each(AtomicFile::commit)
}

/// Prints `line`; the files are already written, so a closed standard output loses nothing.
fn say(line: &str, claimed: &Claimed) -> anyhow::Result<()> {
    console::line(line).with_context(|| {
        format!(
            "cannot print the summary (the files in '{}' are written)",
            claimed.dir().display()
        )
    })
}
