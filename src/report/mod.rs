//! `bench-sph report`: a results directory (or several) becomes PNG charts and `REPORT.md`.
//!
//! The pipeline: [`crate::results::load`] reads `meta.json`, `summary.csv` and `trials.csv`;
//! [`view`] builds one view of each group (its grid and confirmation rows, each cell's runs by
//! round), which every table, chart and finding reads; [`series`] turns it into the series
//! each chart and table needs and [`plan`] into the charts to draw, with their captions (both
//! pure); [`charts`] draws
//! them (one file per chart kind, [`charts::WIDTH`] × [`charts::HEIGHT`] PNGs in the bundled
//! font); [`traces`] finds trace directories to embed; [`markdown`] writes the report's text
//! (pure); [`paper`] holds the seed paper's published numbers.
//!
//! Charts, per group (preset, neighbours, N, steps):
//! 1. runtime against chunks, one line per core count, each line's minimum crossed, each trial
//!    a dot beside its mean, per chunked strategy (the paper's Figure 7);
//! 2. CPU time (user + sys) against chunks, the same way (Figure 8);
//! 3. per strategy, best runtime and best speedup against cores, with the ideal and, for
//!    `seed`/`all-pairs`, the paper's speedups (Figures 9 and 10);
//! 4. every strategy's best speedup against cores, error bars its paired interval;
//! 5. efficiency and the Karp–Flatt serial fraction (with its interval) against cores;
//!
//! where a strategy was measured at several placements (`sweep --pin`), charts 3–5 draw one
//! line per placement and charts 1–2 are drawn per placement ([`plan`]); where the sweep's
//! recorded topology says some core counts put threads on SMT siblings, charts 4–5 shade them
//! and the tables add the efficiency per physical core;
//!
//! and per preset, where both neighbour searches were measured:
//! 6. all-pairs against grid, seconds per step against N.
//!
//! Directories of different machines (by `meta.json`) are not pooled: the report compares the
//! machines instead ([`compare`]).
//!
//! Where the rows hold both the toy workload (`seed`/`cpp`) and `wcsph`, REPORT.md compares
//! the strategy ranking of the two ([`workloads`]) before the groups' sections.
//!
//! A chart that does not apply (no chunked strategy, a single core count, one neighbour
//! search) is not drawn; `REPORT.md` says so. Failed cells enter no chart or table; the report
//! lists them with their reason.

pub mod charts;
pub mod compare;
pub mod findings;
pub mod markdown;
pub mod numbers;
pub mod paper;
pub mod placements;
pub mod plan;
pub mod rank_shift;
pub mod series;
pub mod traces;
pub mod view;
pub mod workloads;

use std::path::{Path, PathBuf};

use anyhow::bail;

use crate::results::load;
pub use crate::results::{REPORT_FILE, is_report_file};
use plan::ChartKind;

/// Whether an entry of a report's directory may stay beside the report: a sweep's own files
/// (the report is often drawn into the sweep's directory) and any directory (traces; the
/// report never writes into subdirectories).
fn tolerated(path: &Path) -> bool {
    use crate::results::{LOCK_FILE, META_FILE, REFERENCES_FILE, SUMMARY_FILE, TRIALS_FILE};
    path.is_dir()
        || path.file_name().and_then(|n| n.to_str()).is_some_and(|n| {
            [
                TRIALS_FILE,
                SUMMARY_FILE,
                META_FILE,
                LOCK_FILE,
                REFERENCES_FILE,
            ]
            .contains(&n)
        })
}

/// Reads the sweeps in `results_dirs`, draws every chart that applies into `out_dir`
/// (claimed first: see [`crate::output::claim`]; `force` writes beside foreign files),
/// embeds the traces found under the results directories and `out_dir` or named in
/// `trace_dirs`, writes `out_dir/REPORT.md`, and removes the charts of an earlier report that
/// this one did not draw again. Cells dropped as impossible are listed on standard error and
/// in the report. Returns the files written, the report last.
///
/// Directories of different machines are not pooled: the report compares them
/// ([`compare`]); see [`generate_with`].
pub fn generate(
    results_dirs: &[PathBuf],
    out_dir: &Path,
    trace_dirs: &[PathBuf],
    force: bool,
) -> anyhow::Result<Vec<PathBuf>> {
    generate_with(
        results_dirs,
        out_dir,
        trace_dirs,
        force,
        compare::SideRule::ByMachine,
    )
}

/// [`generate`], with the directories grouped into sides by `rule`: one side is one study,
/// as always; several sides (several machines, or `--compare`) make a comparison of machines
/// ([`compare`]), whose charts are named `compare-…` and which embeds no trace (traces
/// belong to one machine's full report).
pub fn generate_with(
    results_dirs: &[PathBuf],
    out_dir: &Path,
    trace_dirs: &[PathBuf],
    force: bool,
    rule: compare::SideRule,
) -> anyhow::Result<Vec<PathBuf>> {
    if results_dirs.is_empty() {
        bail!("no results directory given");
    }
    if rule == compare::SideRule::EachDirectory && results_dirs.len() < 2 {
        bail!("--compare needs two results directories or more (each becomes a side)");
    }
    let sweeps = load::load_each(results_dirs)?;
    let sides = compare::sides::sides(&sweeps, rule);
    for side in &sides {
        load::refuse_shared_cells(side.sweeps.iter().copied())?;
    }
    for s in &sweeps {
        for why in &s.dropped {
            crate::output::console::warn(&format!(
                "warning: '{}': row left out of the report: {why}",
                s.dir.display()
            ));
        }
    }
    let comparison = compare::sides::is_comparison(&sides, rule);
    if comparison {
        refuse_comparison_into_an_input(results_dirs, out_dir)?;
    }
    let owns = |p: &Path| p.is_file() && is_report_file(p);
    let owner = crate::output::claim::Owner {
        command: "bench-sph report",
        option: "--out",
        owns: &owns,
        tolerates: &tolerated,
    };
    let claimed = crate::output::claim::claim(out_dir, &owner, force)?;
    claimed.check_writable(REPORT_FILE)?;

    let mut written = Vec::new();
    let text = if comparison {
        if !trace_dirs.is_empty() {
            crate::output::console::warn(
                "warning: --trace is not used when machines are compared: traces belong to \
                 one machine's full report",
            );
        }
        compared(&sweeps, &sides, rule, &claimed, &mut written)?
    } else {
        let traces = (results_dirs, out_dir, trace_dirs);
        // One study: one side, whose views are the study's.
        pooled(&sweeps, &sides[0].views, traces, &claimed, &mut written)?
    };
    let report = out_dir.join(REPORT_FILE);
    crate::output::atomic::write(&report, text.as_bytes())?;
    written.push(report);
    claimed.remove_stale(&written)?;
    Ok(written)
}

/// One study (one machine's directories, whose groups are `views`): draws its charts into
/// `claimed` (adding them to `written`), embeds the traces found from `(results_dirs,
/// out_dir, trace_dirs)` (see [`embed_traces`]), and returns REPORT.md's text.
fn pooled(
    sweeps: &[load::Sweep],
    views: &[view::GroupView],
    (results_dirs, out_dir, trace_dirs): (&[PathBuf], &Path, &[PathBuf]),
    claimed: &crate::output::claim::Claimed,
    written: &mut Vec<PathBuf>,
) -> anyhow::Result<String> {
    let planned = plan::plan(views, |g| markdown::topology_of(sweeps, g));
    for chart in &planned.charts {
        let path = claimed.check_writable(&chart.file)?;
        draw(&path, chart)?;
        written.push(path);
    }
    let traces = embed_traces(results_dirs, out_dir, trace_dirs, written)?;
    Ok(markdown::render(&markdown::Input {
        sweeps,
        views,
        charts: &planned.charts,
        skipped: &planned.skipped,
        traces: &traces,
    }))
}

/// A comparison of `sides`: draws its charts into `claimed` (adding them to `written`) and
/// returns REPORT.md's text.
fn compared(
    sweeps: &[load::Sweep],
    sides: &[compare::sides::Side<'_>],
    rule: compare::SideRule,
    claimed: &crate::output::claim::Claimed,
    written: &mut Vec<PathBuf>,
) -> anyhow::Result<String> {
    let planned = compare::plan::plan(sides);
    for chart in planned.compared.iter().flat_map(|c| &c.charts) {
        let path = claimed.check_writable(&chart.file)?;
        charts::compare::draw(&path, &chart.title, &chart.subtitle, &chart.lines)?;
        written.push(path);
    }
    Ok(compare::markdown::render(&compare::markdown::Input {
        sweeps,
        sides,
        rule,
        plan: &planned,
    }))
}

/// The traces found under the results directories and `out_dir` or named in `trace_dirs`;
/// their timelines are copied into `out_dir` where needed (and added to `written`).
fn embed_traces(
    results_dirs: &[PathBuf],
    out_dir: &Path,
    trace_dirs: &[PathBuf],
    written: &mut Vec<PathBuf>,
) -> anyhow::Result<Vec<traces::TraceDir>> {
    let mut roots = results_dirs.to_vec();
    roots.push(out_dir.to_path_buf());
    let found = traces::find(&roots, trace_dirs)?;
    let mut copied = Vec::new();
    let traces = found
        .iter()
        .map(|d| traces::read(d, out_dir, &mut copied))
        .collect::<anyhow::Result<Vec<_>>>()?;
    for t in &traces {
        if !t.image.contains('/') {
            written.push(out_dir.join(&t.image));
        }
    }
    Ok(traces)
}

/// A comparison of machines belongs to none of them: written into one of the results
/// directories, it would replace that sweep's own REPORT.md and remove its charts as stale.
fn refuse_comparison_into_an_input(results_dirs: &[PathBuf], out_dir: &Path) -> anyhow::Result<()> {
    let Ok(out) = out_dir.canonicalize() else {
        return Ok(());
    };
    if let Some(dir) = results_dirs
        .iter()
        .find(|d| d.canonicalize().is_ok_and(|d| d == out))
    {
        bail!(
            "these directories are compared, not pooled, and the comparison would replace \
             '{}''s own report: write it elsewhere with --out DIR",
            dir.display()
        );
    }
    Ok(())
}

/// Draws one planned chart into `path`.
fn draw(path: &Path, chart: &plan::ChartPlan) -> anyhow::Result<()> {
    let (title, subtitle) = (chart.title.as_str(), chart.subtitle.as_str());
    match &chart.kind {
        ChartKind::Chunks {
            y_desc,
            lines,
            mark_min,
        } => charts::chunks::draw(path, title, subtitle, y_desc, lines, *mark_min),
        ChartKind::Best(data) => charts::best::draw(path, title, subtitle, data),
        ChartKind::Speedup { lines, smt } => {
            charts::speedup::draw(path, title, subtitle, lines, smt.as_ref())
        }
        ChartKind::Efficiency {
            efficiency,
            serial,
            smt,
        } => charts::efficiency::draw(path, title, subtitle, (efficiency, serial), smt.as_ref()),
        ChartKind::Neighbors(lines) => charts::neighbors::draw(path, title, subtitle, lines),
    }
}
