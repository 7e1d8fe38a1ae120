//! `bench-sph report`: a results directory (or several) becomes PNG charts and `REPORT.md`.
//!
//! The pipeline: [`sph_harness::results::load`] reads `meta.json`, `summary.csv` and `trials.csv`;
//! [`view`] builds one view of each group (its grid and confirmation rows, each cell's runs by
//! round: [`cell`]; which rows form a series: [`select`]), which every table, chart and
//! finding reads; [`verdict`] orders two cells by their paired rounds and decides the fastest
//! of a core count, for the findings and the comparisons; [`series`] turns it into the series
//! each chart and table needs and [`plan`] into the charts to draw, with their captions (both
//! pure); [`charts`] draws
//! them (one file per chart kind, [`charts::WIDTH`] × [`charts::HEIGHT`] PNGs in the bundled
//! font); [`traces`] finds trace directories to embed; [`markdown`] writes the report's text
//! (pure), opening with [`answer`] (per group and core count, the fastest strategy as the
//! group's findings decide it), every table through [`table`]; [`paper`] holds the seed
//! paper's published numbers.
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

pub mod answer;
pub mod bends;
pub mod cell;
pub mod charts;
pub mod compare;
pub mod findings;
pub mod markdown;
pub mod numbers;
pub mod paper;
pub mod placements;
pub mod plan;
pub mod rank_shift;
pub mod select;
pub mod series;
pub mod table;
pub mod traces;
pub mod verdict;
pub mod view;
pub mod workloads;

use std::path::{Path, PathBuf};

use anyhow::bail;

use plan::ChartKind;
use sph_harness::output::claim::{self, Claimed, Owner};
use sph_harness::output::record::Command;
pub use sph_harness::results::REPORT_FILE;
use sph_harness::results::load;

/// Reads the sweeps in `results_dirs`, draws every chart that applies into `out_dir`
/// (claimed first: see [`sph_harness::output::claim`]; `force` writes beside foreign files),
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
///
/// Every file the report will write (charts, copied timelines, REPORT.md) is planned and
/// checked first: a name taken by a directory, or by a file the directory's record does not
/// give to the report, stops it before anything is written.
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
            sph_harness::output::console::warn(&format!(
                "warning: '{}': row left out of the report: {why}",
                s.dir.display()
            ));
        }
    }
    let comparison = compare::sides::is_comparison(&sides, rule);
    if comparison {
        refuse_comparison_into_an_input(results_dirs, out_dir)?;
    }
    // The plan: every file to write, checked before any is written.
    let drawing = if comparison {
        if !trace_dirs.is_empty() {
            sph_harness::output::console::warn(
                "warning: --trace is not used when machines are compared: traces belong to \
                 one machine's full report",
            );
        }
        Drawing::Compared(compare::plan::plan(&sides))
    } else {
        let views = &sides[0].views;
        Drawing::Pooled {
            planned: plan::plan(views, |g| markdown::topology_of(&sweeps, g)),
            traces: find_traces(results_dirs, out_dir, trace_dirs)?,
        }
    };
    let mut files = drawing.files();
    files.push(REPORT_FILE.to_owned());
    let mut claimed = claim_out(results_dirs, out_dir, &files, force)?;
    let paths = files
        .iter()
        .map(|f| claimed.check_writable(f))
        .collect::<anyhow::Result<Vec<_>>>()?;
    claimed.record(&files)?;

    // Then the drawing, file by file (each whole or not at all), and the text.
    let text = match &drawing {
        Drawing::Compared(planned) => {
            for chart in planned.compared.iter().flat_map(|c| &c.charts) {
                draw(&out_dir.join(&chart.file), chart)?;
            }
            compare::markdown::render(&compare::markdown::Input {
                sweeps: &sweeps,
                sides: &sides,
                rule,
                plan: planned,
            })
        }
        Drawing::Pooled { planned, traces } => {
            for chart in &planned.charts {
                draw(&out_dir.join(&chart.file), chart)?;
            }
            for copy in traces.iter().filter_map(|(_, copy)| copy.as_ref()) {
                traces::copy(copy, &out_dir.join(&copy.file))?;
            }
            let traces: Vec<traces::TraceDir> = traces.iter().map(|(t, _)| t.clone()).collect();
            markdown::render(&markdown::Input {
                sweeps: &sweeps,
                views: &sides[0].views,
                charts: &planned.charts,
                skipped: &planned.skipped,
                traces: &traces,
            })
        }
    };
    let report = out_dir.join(REPORT_FILE);
    sph_harness::output::atomic::write(&report, text.as_bytes())?;
    claimed.remove_stale(&paths)?;
    // Said once the report is written (a refused report has nothing to qualify).
    for s in sweeps.iter().filter(|s| s.without_trials) {
        sph_harness::output::console::warn(&format!(
            "warning: '{}' has no trials.csv: the statistics in its summary.csv could not be \
             checked against the runs (they are taken on trust) and its findings are withheld. \
             {}",
            s.dir.display(),
            markdown::UNCHECKED_ADVICE
        ));
    }
    Ok(paths)
}

/// What a report draws: one study's charts and traces, or a comparison's charts.
enum Drawing {
    /// One study (one machine's directories): its charts, and the traces it embeds with the
    /// timelines to copy.
    Pooled {
        planned: plan::ReportPlan,
        traces: Vec<(traces::TraceDir, Option<traces::TimelineCopy>)>,
    },
    /// A comparison of machines.
    Compared(compare::plan::ComparePlan),
}

impl Drawing {
    /// The files it writes into the report's directory, in the order it writes them.
    fn files(&self) -> Vec<String> {
        match self {
            Drawing::Pooled { planned, traces } => planned
                .charts
                .iter()
                .map(|c| c.file.clone())
                .chain(
                    traces
                        .iter()
                        .filter_map(|(_, c)| c.as_ref().map(|c| c.file.clone())),
                )
                .collect(),
            Drawing::Compared(planned) => planned
                .compared
                .iter()
                .flat_map(|c| &c.charts)
                .map(|c| c.file.clone())
                .collect(),
        }
    }
}

/// Locks and claims the report's directory, where it will write `files`. It leaves alone the
/// results of a sweep or merge recorded there, subdirectories (traces: the report never
/// writes into one), and, when it is one of the results directories read, that directory's
/// own files — the report's input, which an older version left without a record.
fn claim_out(
    results_dirs: &[PathBuf],
    out_dir: &Path,
    files: &[String],
    force: bool,
) -> anyhow::Result<Claimed> {
    let out = out_dir.canonicalize().ok();
    let is_input = out.is_some() && results_dirs.iter().any(|d| d.canonicalize().ok() == out);
    let tolerated = |path: &Path| {
        use sph_harness::results::{META_FILE, REFERENCES_FILE, SUMMARY_FILE, TRIALS_FILE};
        path.is_dir()
            || is_input
                && path.file_name().and_then(|n| n.to_str()).is_some_and(|n| {
                    [TRIALS_FILE, SUMMARY_FILE, META_FILE, REFERENCES_FILE].contains(&n)
                })
    };
    let writes: Vec<&str> = files.iter().map(String::as_str).collect();
    let owner = Owner {
        command: Command::Report,
        option: "--out",
        replaces: &[],
        tolerates: &[Command::Sweep, Command::Merge],
        tolerates_unrecorded: &tolerated,
        writes: &writes,
    };
    claim::claim(out_dir, &owner, force)
}

/// The traces found under the results directories and `out_dir` or named in `trace_dirs`,
/// each read and validated, with the timeline to copy into `out_dir` where it lies outside.
fn find_traces(
    results_dirs: &[PathBuf],
    out_dir: &Path,
    trace_dirs: &[PathBuf],
) -> anyhow::Result<Vec<(traces::TraceDir, Option<traces::TimelineCopy>)>> {
    let mut roots = results_dirs.to_vec();
    roots.push(out_dir.to_path_buf());
    let found = traces::find(&roots, trace_dirs)?;
    let mut copied = Vec::new();
    found
        .iter()
        .map(|d| traces::read(d, out_dir, &mut copied))
        .collect()
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
        ChartKind::Machines { lines, .. } => charts::compare::draw(path, title, subtitle, lines),
    }
}
