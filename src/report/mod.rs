//! `bench-sph report`: a results directory (or several) becomes PNG charts and `REPORT.md`.
//!
//! The pipeline: [`load`] reads `meta.json` and `summary.csv` into the sweep's own types;
//! [`series`] turns rows into the series each chart and table needs (pure); [`charts`] draws
//! them (one file per chart kind, [`charts::WIDTH`] × [`charts::HEIGHT`] PNGs in the bundled
//! font); [`traces`] finds trace directories to embed; [`markdown`] writes the report's text
//! (pure); [`paper`] holds the seed paper's published numbers.
//!
//! Charts, per group (preset, neighbours, N, steps):
//! 1. runtime against chunks, one line per core count, each line's minimum crossed, per chunked
//!    strategy (the paper's Figure 7);
//! 2. CPU time (user + sys) against chunks, the same way (Figure 8);
//! 3. per strategy, best runtime and best speedup against cores, with the ideal and, for
//!    `seed`/`all-pairs`, the paper's speedups (Figures 9 and 10);
//! 4. every strategy's best speedup against cores, error bars from the trial spread;
//! 5. efficiency and the Karp–Flatt serial fraction against cores;
//!
//! and per preset, where both neighbour searches were measured:
//! 6. all-pairs against grid, seconds per step against N.
//!
//! A chart that does not apply (no chunked strategy, a single core count, one neighbour
//! search) is not drawn; `REPORT.md` says so. Failed cells enter no chart or table; the report
//! lists them with their reason.

pub mod charts;
pub mod findings;
pub mod markdown;
pub mod numbers;
pub mod paper;
pub mod series;
pub mod traces;

use std::path::{Path, PathBuf};

use anyhow::bail;

use crate::results::load;
pub use crate::results::{REPORT_FILE, is_report_file};
use markdown::{ChartRef, Skipped};
use series::{Group, Metric};
use sph_strategies::StrategyName;

/// Whether an entry of a report's directory may stay beside the report: a sweep's own files
/// (the report is often drawn into the sweep's directory) and any directory (traces; the
/// report never writes into subdirectories).
fn tolerated(path: &Path) -> bool {
    use crate::results::{LOCK_FILE, META_FILE, SUMMARY_FILE, TRIALS_FILE};
    path.is_dir()
        || path
            .file_name()
            .and_then(|n| n.to_str())
            .is_some_and(|n| [TRIALS_FILE, SUMMARY_FILE, META_FILE, LOCK_FILE].contains(&n))
}

/// Reads the sweeps in `results_dirs`, draws every chart that applies into `out_dir`
/// (claimed first: see [`crate::output::claim`]; `force` writes beside foreign files),
/// embeds the traces found under the results directories and `out_dir` or named in
/// `trace_dirs`, writes `out_dir/REPORT.md`, and removes the charts of an earlier report that
/// this one did not draw again. Cells dropped as impossible are listed on standard error and
/// in the report. Returns the files written, the report last.
pub fn generate(
    results_dirs: &[PathBuf],
    out_dir: &Path,
    trace_dirs: &[PathBuf],
    force: bool,
) -> anyhow::Result<Vec<PathBuf>> {
    if results_dirs.is_empty() {
        bail!("no results directory given");
    }
    let sweeps = load::load_all(results_dirs)?;
    for s in &sweeps {
        for why in &s.dropped {
            crate::output::console::warn(&format!(
                "warning: '{}': row left out of the report: {why}",
                s.dir.display()
            ));
        }
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
    let rows: Vec<_> = sweeps.iter().flat_map(|s| s.rows.clone()).collect();

    let mut written = Vec::new();
    let mut refs = Vec::new();
    let mut skipped = Vec::new();
    let mut chart = |file: String, group: Option<&Group>, caption: String| {
        refs.push(ChartRef {
            group: group.cloned(),
            file: file.clone(),
            caption,
        });
        claimed.check_writable(&file)
    };

    for g in series::groups(&rows) {
        let subtitle = g.label(crate::results::key::LabelStyle::Report);
        let skip = |note: String| Skipped {
            group: Some(g),
            note,
        };
        let strategies = series::strategies(&rows, &g);
        let chunked: Vec<StrategyName> = strategies
            .iter()
            .copied()
            .filter(|&s| series::is_chunked(&rows, &g, s))
            .collect();
        if chunked.is_empty() {
            skipped.push(skip(
                "Charts 1–2 (time against chunks) are not drawn: no strategy with chunks was \
                 measured in this group."
                    .to_owned(),
            ));
        }
        for s in chunked {
            for (metric, n, what, y_desc) in [
                (Metric::Wall, 1, "runtime", "mean runtime (s)"),
                (Metric::Cpu, 2, "cpu", "mean CPU time, user + sys (s)"),
            ] {
                let lines = series::chunk_lines(&rows, &g, s, metric);
                if lines.is_empty() {
                    continue;
                }
                let (title, caption) = match metric {
                    Metric::Wall => (
                        format!("Runtime against chunks: {s}"),
                        format!(
                            "Chart 1: {s}, mean runtime against chunks per pass, one line per core \
                             count, each line's minimum crossed (the paper's Figure 7); {subtitle}."
                        ),
                    ),
                    Metric::Cpu => (
                        format!("CPU time against chunks: {s}"),
                        format!(
                            "Chart 2: {s}, mean CPU time (user + sys) against chunks per pass, \
                             one line per core count (the paper's Figure 8); {subtitle}."
                        ),
                    ),
                };
                let path = chart(
                    format!("{}-{n}-{what}-vs-chunks-{s}.png", g.slug()),
                    Some(&g),
                    caption,
                )?;
                charts::chunks::draw(
                    &path,
                    &title,
                    &subtitle,
                    y_desc,
                    &lines,
                    metric == Metric::Wall,
                )?;
                written.push(path);
            }
        }

        let cores = series::cores(&rows, &g);
        let seq = series::seq_mean(&rows, &g);
        match seq {
            Some(seq_s) if cores.len() > 1 => {
                let comparable = paper::comparable(&g);
                for s in strategies
                    .iter()
                    .copied()
                    .filter(|&s| s != StrategyName::Seq)
                {
                    let best = series::best_per_cores(&rows, &g, s);
                    if best.len() < 2 {
                        continue;
                    }
                    let speedup = series::speedup_lines(&rows, &g)
                        .into_iter()
                        .find(|l| l.label == s.as_str());
                    let Some(speedup) = speedup else { continue };
                    let data = charts::best::BestChart {
                        strategy: s.as_str(),
                        runtime: series::runtime_line(&best, s.as_str()),
                        speedup,
                        seq_s,
                        paper: comparable,
                    };
                    let caption = format!(
                        "Chart 3: {s}, best runtime (above) and best speedup (below) against cores, \
                         bars: 95 % confidence intervals{} (the paper's Figures 9 and 10); \
                         {subtitle}.",
                        if comparable {
                            "; grey triangles: the paper's published speedups on its own machine, \
                             at the core counts measured here"
                        } else {
                            ""
                        }
                    );
                    let path = chart(format!("{}-3-best-{s}.png", g.slug()), Some(&g), caption)?;
                    charts::best::draw(
                        &path,
                        &format!("Best runtime and speedup against cores: {s}"),
                        &subtitle,
                        &data,
                    )?;
                    written.push(path);
                }
                let lines = series::speedup_lines(&rows, &g);
                let path = chart(
                    format!("{}-4-speedup.png", g.slug()),
                    Some(&g),
                    format!(
                        "Chart 4: every strategy's best speedup against cores, error bars the 95 % \
                         bootstrap interval of the best cell's speedup; {subtitle}."
                    ),
                )?;
                charts::speedup::draw(
                    &path,
                    "Speedup against cores, every strategy",
                    &subtitle,
                    &lines,
                )?;
                written.push(path);
                let (eff, kf) = series::efficiency_lines(&rows, &g);
                let path = chart(
                    format!("{}-5-efficiency.png", g.slug()),
                    Some(&g),
                    format!(
                        "Chart 5: parallel efficiency S/p (above) and the Karp–Flatt serial fraction \
                         e = (1/S − 1/p)/(1 − 1/p) (below, only where S > 1 and p > 1) against \
                         cores; {subtitle}."
                    ),
                )?;
                charts::efficiency::draw(
                    &path,
                    "Efficiency and Karp–Flatt serial fraction against cores",
                    &subtitle,
                    &eff,
                    &kf,
                )?;
                written.push(path);
            }
            Some(_) => skipped.push(skip(match cores.first() {
                Some(&c) => format!(
                    "Charts 3–5 (against cores) are not drawn: only {} was measured.",
                    series::cores_label(c)
                ),
                None => "Charts 3–5 (against cores) are not drawn: no parallel strategy has a \
                         usable cell."
                    .to_owned(),
            })),
            None => skipped.push(skip(
                "Charts 3–5 (against cores) are not drawn: there is no usable seq reference."
                    .to_owned(),
            )),
        }
    }

    for preset in series::presets(&rows) {
        match series::neighbor_lines(&rows, preset) {
            Some(lines) if !lines.is_empty() => {
                let path = chart(
                    format!("{preset}-6-neighbors.png"),
                    None,
                    format!(
                        "Chart 6: all-pairs against grid, seconds per step against N ({preset} \
                         preset), for seq and for the fastest parallel cell, one line per step \
                         count (runs of different lengths are never joined); bars: 95 % \
                         confidence intervals."
                    ),
                )?;
                charts::neighbors::draw(
                    &path,
                    "All-pairs against grid: time per step against N",
                    &format!("{preset} preset; seq at 1 core and the fastest parallel cell"),
                    &lines,
                )?;
                written.push(path);
            }
            _ => skipped.push(Skipped {
                group: None,
                note: format!(
                    "Chart 6 (all-pairs against grid) is not drawn for the {preset} preset: the \
                     results hold only one neighbour search."
                ),
            }),
        }
    }

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

    let text = markdown::render(&markdown::Input {
        sweeps: &sweeps,
        charts: &refs,
        skipped: &skipped,
        traces: &traces,
    });
    let report = out_dir.join(REPORT_FILE);
    crate::output::atomic::write(&report, text.as_bytes())?;
    written.push(report);
    claimed.remove_stale(&written)?;
    Ok(written)
}
