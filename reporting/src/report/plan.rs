//! Which charts a report draws, as data: for each chart its file name, caption, titles and
//! series, and for each chart that does not apply, why. A pure function of the groups' views
//! and the machine's topology ([`plan`]); [`super::generate`] then only draws each
//! [`ChartPlan`] and writes the text (criterion's "compute the series, then draw"). Charts
//! 1–2 show the grid (every cell, each trial a dot); charts 3–5 each strategy's best cells,
//! as the tables do ([`GroupView::best_per_cores`]).
//!
//! Placements (`sweep --pin`): charts 3–5 draw one line per strategy and placement, the
//! pinned ones in the strategy's colour, dashed (`spread`) or dotted (`compact`); charts 1–2
//! are drawn once per strategy and placement (the unpinned one under its usual name, a
//! pinned one with `-pin-spread` or `-pin-compact` added), since their lines are already the
//! core counts. Where the topology says some core counts put threads on SMT siblings,
//! charts 4–5 shade them.

use sph_strategies::StrategyName;

use super::cell;
use super::charts::best::BestChart;
use super::charts::compare::MachineLines;
use super::paper;
use super::select;
use super::select::SeriesKey;
use super::series::{self, Line, Metric, SmtBand};
use super::view::GroupView;
use sph_harness::results::key::{Group, LabelStyle};
use sph_harness::results::rows::SummaryRow;
use sph_harness::topology::{Pin, Topology};
use sph_solver::models::Preset;

/// A chart that does not apply, and why.
#[derive(Debug, Clone, PartialEq)]
pub struct Skipped {
    /// The group (`None` for charts across groups).
    pub group: Option<Group>,
    /// E.g. `Chart 6 (all-pairs vs grid)`, and why it is not drawn.
    pub note: String,
}

/// What a chart shows, with its series.
#[derive(Debug, Clone)]
pub enum ChartKind {
    /// Charts 1 and 2: `metric` against chunks, one line per core count.
    Chunks {
        /// The y axis' description.
        y_desc: &'static str,
        /// One line per core count.
        lines: Vec<Line>,
        /// Whether each line's minimum is crossed (runtime, not CPU time).
        mark_min: bool,
    },
    /// Chart 3: one strategy's best runtime and speedup against cores.
    Best(BestChart<'static>),
    /// Chart 4: every strategy's best speedup against cores.
    Speedup {
        /// One line per series.
        lines: Vec<Line>,
        /// The core counts to shade as SMT siblings.
        smt: Option<SmtBand>,
    },
    /// Chart 5: efficiency and the Karp–Flatt serial fraction against cores.
    Efficiency {
        /// Efficiency lines.
        efficiency: Vec<Line>,
        /// Serial-fraction lines.
        serial: Vec<Line>,
        /// The core counts to shade as SMT siblings.
        smt: Option<SmtBand>,
    },
    /// Chart 6: all-pairs against grid, seconds per step against N.
    Neighbors(Vec<Line>),
    /// A comparison of machines: one strategy's best speedup and efficiency against cores,
    /// one line per machine.
    Machines {
        /// The strategy.
        strategy: StrategyName,
        /// One entry per machine with a speedup line, by side.
        lines: Vec<MachineLines>,
    },
}

/// One chart to draw.
#[derive(Debug, Clone)]
pub struct ChartPlan {
    /// File name, relative to the report.
    pub file: String,
    /// The group it belongs to (`None` for charts across groups, and for a comparison's
    /// charts, whose workload is one group on each machine).
    pub group: Option<Group>,
    /// The report's one-sentence caption.
    pub caption: String,
    /// The title drawn on the chart.
    pub title: String,
    /// The subtitle drawn under it.
    pub subtitle: String,
    /// The series.
    pub kind: ChartKind,
}

impl ChartPlan {
    /// The image's alt text: the caption up to its first `;` or `,`, or for a comparison the
    /// strategy and what the chart shows.
    pub fn alt(&self) -> String {
        match &self.kind {
            ChartKind::Machines { strategy, .. } => {
                format!("{strategy}: speedup and efficiency against cores, per machine")
            }
            _ => {
                let caption = self.caption.as_str();
                caption
                    .split([';', ','])
                    .next()
                    .unwrap_or(caption)
                    .to_owned()
            }
        }
    }
}

/// Every chart of a report, in the order drawn, and the notes on those not drawn.
#[derive(Debug, Clone, Default)]
pub struct ReportPlan {
    /// Charts to draw, group by group, then the charts across groups.
    pub charts: Vec<ChartPlan>,
    /// Charts that do not apply, and why.
    pub skipped: Vec<Skipped>,
}

/// The charts of `views` (see the module docs of [`super`] for the list); `topology` gives
/// the recorded topology of the machine that measured a group, where known.
pub fn plan<'t>(
    views: &[GroupView],
    topology: impl Fn(&Group) -> Option<&'t Topology>,
) -> ReportPlan {
    let mut out = ReportPlan::default();
    for v in views {
        chunk_charts(v, &mut out);
        let cores = v.cores();
        let smt = topology(&v.group).and_then(|t| series::smt_band(t, &cores));
        cores_charts(v, smt, &mut out);
    }
    let rows: Vec<SummaryRow> = views.iter().flat_map(|v| v.rows.clone()).collect();
    for preset in series::presets(&rows) {
        neighbor_chart(&rows, preset, &mut out);
    }
    out
}

impl ReportPlan {
    fn skip(&mut self, group: &Group, note: &str) {
        self.skipped.push(Skipped {
            group: Some(*group),
            note: note.to_owned(),
        });
    }

    fn chart(
        &mut self,
        group: &Group,
        file: String,
        title: String,
        caption: String,
        kind: ChartKind,
    ) {
        self.charts.push(ChartPlan {
            file,
            group: Some(*group),
            caption,
            title,
            subtitle: group.label(LabelStyle::Report),
            kind,
        });
    }
}

/// Charts 1 and 2 for each chunked strategy of `v`, at each of its placements.
fn chunk_charts(v: &GroupView, out: &mut ReportPlan) {
    let (rows, g) = (&v.rows, &v.group);
    let subtitle = g.label(LabelStyle::Report);
    let chunked: Vec<StrategyName> = select::strategies(rows, g)
        .into_iter()
        .filter(|&s| select::is_chunked(rows, g, s))
        .collect();
    if chunked.is_empty() {
        out.skip(
            g,
            "Charts 1–2 (time against chunks) are not drawn: no strategy with chunks was \
             measured in this group.",
        );
    }
    let keys = chunked.into_iter().flat_map(|s| {
        select::pins(rows, g, s)
            .into_iter()
            .map(move |p| SeriesKey::new(s, p))
    });
    for key in keys {
        for (metric, n, what, y_desc) in [
            (Metric::Wall, 1, "runtime", "mean runtime (s)"),
            (Metric::Cpu, 2, "cpu", "mean CPU time, user + sys (s)"),
        ] {
            let lines = series::chunk_lines(v, key, metric);
            if lines.is_empty() {
                continue;
            }
            let (title, caption) = match metric {
                Metric::Wall => (
                    format!("Runtime against chunks: {key}"),
                    format!(
                        "Chart 1: {key}, mean runtime against chunks per pass over the grid's \
                         rounds, one line per core count, each line's minimum crossed, bars \
                         the 95 % interval, each trial a small dot beside its mean (the paper's \
                         Figure 7); {subtitle}."
                    ),
                ),
                Metric::Cpu => (
                    format!("CPU time against chunks: {key}"),
                    format!(
                        "Chart 2: {key}, mean CPU time (user + sys) against chunks per pass, \
                         one line per core count (the paper's Figure 8); {subtitle}."
                    ),
                ),
            };
            let pinned = match key.pin {
                Pin::None => String::new(),
                pin => format!("-pin-{pin}"),
            };
            let file = format!(
                "{}-{n}-{what}-vs-chunks-{}{pinned}.png",
                g.slug(),
                key.strategy
            );
            let mark_min = metric == Metric::Wall;
            let kind = ChartKind::Chunks {
                y_desc,
                lines,
                mark_min,
            };
            out.chart(g, file, title, caption, kind);
        }
    }
}

/// Charts 3–5 of `v`, or why they are not drawn.
fn cores_charts(v: &GroupView, smt: Option<SmtBand>, out: &mut ReportPlan) {
    let g = &v.group;
    let cores = v.cores();
    match v.reference().and_then(|r| r.mean_s) {
        Some(seq_s) if cores.len() > 1 => {
            let bests = v.series_bests();
            best_charts(v, &bests, seq_s, out);
            speedup_and_efficiency_charts(g, &bests, smt, out);
        }
        Some(_) => match cores.first() {
            Some(&c) => out.skip(
                g,
                &format!(
                    "Charts 3–5 (against cores) are not drawn: only {} was measured.",
                    series::cores_label(c)
                ),
            ),
            None => out.skip(
                g,
                "Charts 3–5 (against cores) are not drawn: no parallel strategy has a usable \
                 cell.",
            ),
        },
        None => out.skip(
            g,
            "Charts 3–5 (against cores) are not drawn: there is no usable seq reference.",
        ),
    }
}

/// Chart 3 for each strategy of `v` with at least two core counts (at some placement), one
/// line per placement; `bests` are its series' best cells.
fn best_charts(
    v: &GroupView,
    bests: &[(SeriesKey, Vec<cell::Best>)],
    seq_s: f64,
    out: &mut ReportPlan,
) {
    let g = &v.group;
    let subtitle = g.label(LabelStyle::Report);
    let comparable = paper::comparable(g);
    let speedups = series::speedup_lines(bests);
    for s in v.parallel_strategies() {
        let mut runtime = Vec::new();
        let mut speedup = Vec::new();
        for (key, best) in bests.iter().filter(|(k, _)| k.strategy == s) {
            let line = speedups.iter().find(|l| l.series == Some(*key));
            if let (false, Some(line)) = (best.is_empty(), line) {
                runtime.push(series::runtime_line(best, *key));
                speedup.push(line.clone());
            }
        }
        if runtime.iter().all(|l| l.points.len() < 2) {
            continue;
        }
        let keys: Vec<SeriesKey> = speedup.iter().filter_map(|l| l.series).collect();
        let data = BestChart {
            strategy: s.as_str(),
            runtime,
            speedup,
            seq_s,
            paper: comparable,
        };
        let caption = format!(
            "Chart 3: {s}, best runtime (above) and best speedup (below) against cores{}, \
             bars: 95 % confidence intervals{} (the paper's Figures 9 and 10){}; {subtitle}.",
            chosen(v),
            if comparable {
                "; grey triangles: the paper's published speedups on its own machine, at the \
                 core counts measured here"
            } else {
                ""
            },
            line_styles(&keys),
        );
        let file = format!("{}-3-best-{s}.png", g.slug());
        let title = format!("Best runtime and speedup against cores: {s}");
        out.chart(g, file, title, caption, ChartKind::Best(data));
    }
}

/// How charts 3–5 say where their best cells come from.
fn chosen(v: &GroupView) -> &'static str {
    if v.is_confirmed() {
        " (each best cell as the confirmation rounds measured it)"
    } else {
        " (each best cell as the grid's rounds that chose it measured it: biased fast)"
    }
}

/// Charts 4 and 5 of `g`, from the best cells `bests`, with the core counts in `smt` shaded.
fn speedup_and_efficiency_charts(
    g: &Group,
    bests: &[(SeriesKey, Vec<cell::Best>)],
    smt: Option<SmtBand>,
    out: &mut ReportPlan,
) {
    let subtitle = g.label(LabelStyle::Report);
    let lines = series::speedup_lines(bests);
    let keys: Vec<SeriesKey> = lines.iter().filter_map(|l| l.series).collect();
    let styles = line_styles(&keys);
    let shaded = smt.as_ref().map_or_else(String::new, |b| {
        format!(
            "; shaded: the core counts past the machine's {} that put threads on SMT \
             siblings",
            sph_harness::output::console::plural(
                b.physical_cores,
                "physical core",
                "physical cores"
            )
        )
    });
    out.chart(
        g,
        format!("{}-4-speedup.png", g.slug()),
        "Speedup against cores, every strategy".to_owned(),
        format!(
            "Chart 4: every strategy's best speedup against cores, error bars the 95 % \
             interval of the best cell's speedup paired by round{styles}{shaded}; {subtitle}."
        ),
        ChartKind::Speedup {
            lines,
            smt: smt.clone(),
        },
    );
    let (efficiency, serial) = series::efficiency_lines(bests);
    let per_physical = if smt.is_some() {
        " (the tables give the efficiency per physical core)"
    } else {
        ""
    };
    out.chart(
        g,
        format!("{}-5-efficiency.png", g.slug()),
        "Efficiency and Karp–Flatt serial fraction against cores".to_owned(),
        format!(
            "Chart 5: parallel efficiency S/p (above) and the Karp–Flatt serial fraction \
             e = (1/S − 1/p)/(1 − 1/p) with its 95 % interval (below, only where S > 1 and \
             the interval lies above 0) against cores{styles}{shaded}{per_physical}; \
             {subtitle}."
        ),
        ChartKind::Efficiency {
            efficiency,
            serial,
            smt,
        },
    );
}

/// How a caption names the line styles of pinned series among `keys` (nothing where every
/// series is unpinned): `; solid: unpinned, dashed: pinned spread`.
fn line_styles(keys: &[SeriesKey]) -> String {
    let pins: std::collections::BTreeSet<Pin> = keys.iter().map(|k| k.pin).collect();
    if pins.iter().all(|&p| p == Pin::None) {
        return String::new();
    }
    let parts: Vec<String> = pins
        .iter()
        .map(|&p| match p {
            Pin::None => "solid: unpinned (`--pin none`)".to_owned(),
            pin => format!("{}: pinned `{pin}`", super::charts::Dash::of(pin).as_str()),
        })
        .collect();
    format!("; {}", parts.join(", "))
}

/// Chart 6 of `preset`, or why it is not drawn.
fn neighbor_chart(rows: &[SummaryRow], preset: Preset, out: &mut ReportPlan) {
    match series::neighbor_lines(rows, preset) {
        Some(lines) if !lines.is_empty() => out.charts.push(ChartPlan {
            file: format!("{preset}-6-neighbors.png"),
            group: None,
            caption: format!(
                "Chart 6: all-pairs against grid, seconds per step against N ({preset} \
                 preset), for seq and for the fastest parallel cell, one line per step \
                 count (runs of different lengths are never joined); bars: 95 % \
                 confidence intervals."
            ),
            title: "All-pairs against grid: time per step against N".to_owned(),
            subtitle: format!("{preset} preset; seq at 1 core and the fastest parallel cell"),
            kind: ChartKind::Neighbors(lines),
        }),
        _ => out.skipped.push(Skipped {
            group: None,
            note: format!(
                "Chart 6 (all-pairs against grid) is not drawn for the {preset} preset: the \
                 results hold only one neighbour search."
            ),
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use sph_harness::results::fixtures::row;
    use sph_solver::sph::neighbors::NeighborMode;

    /// The plan of `rows` (no trials), the topology `topology`.
    fn plan_of(rows: &[SummaryRow], topology: Option<&Topology>) -> ReportPlan {
        let views = crate::report::view::tests::views(rows.to_vec(), Vec::new());
        plan(&views, |_| topology)
    }

    fn files(p: &ReportPlan) -> Vec<&str> {
        p.charts.iter().map(|c| c.file.as_str()).collect()
    }

    #[test]
    fn a_group_with_chunks_and_several_core_counts_gets_charts_one_to_five_in_order() {
        let rows = vec![
            row(StrategyName::Seq, 1, None, 4.0),
            row(StrategyName::RayonChunks, 1, Some(5), 4.1),
            row(StrategyName::RayonChunks, 2, Some(5), 2.5),
            row(StrategyName::RayonChunks, 2, Some(10), 2.2),
        ];
        let p = plan_of(&rows, None);
        assert_eq!(
            files(&p),
            [
                "seed-all-pairs-n60-s3-1-runtime-vs-chunks-rayon-chunks.png",
                "seed-all-pairs-n60-s3-2-cpu-vs-chunks-rayon-chunks.png",
                "seed-all-pairs-n60-s3-3-best-rayon-chunks.png",
                "seed-all-pairs-n60-s3-4-speedup.png",
                "seed-all-pairs-n60-s3-5-efficiency.png",
            ]
        );
        assert!(
            p.charts[2].caption.contains("grey triangles"),
            "seed/all-pairs is the paper's"
        );
        assert!(
            p.charts
                .iter()
                .all(|c| c.subtitle == "seed preset, all-pairs, N = 60, 3 steps")
        );
        let notes: Vec<&str> = p.skipped.iter().map(|s| s.note.as_str()).collect();
        assert_eq!(notes.len(), 1, "{notes:?}");
        assert!(notes[0].starts_with("Chart 6 (all-pairs against grid) is not drawn for the seed"));
    }

    #[test]
    fn a_pinned_placement_gets_its_own_chunks_charts_and_dashed_lines_in_charts_three_to_five() {
        use crate::report::series::tests::pinned;
        let rows = vec![
            row(StrategyName::Seq, 1, None, 4.0),
            row(StrategyName::RayonChunks, 1, Some(5), 4.1),
            row(StrategyName::RayonChunks, 2, Some(5), 2.5),
            pinned(row(StrategyName::RayonChunks, 1, Some(5), 4.0), Pin::Spread),
            pinned(row(StrategyName::RayonChunks, 2, Some(5), 2.1), Pin::Spread),
        ];
        let p = plan_of(&rows, None);
        assert_eq!(
            files(&p),
            [
                "seed-all-pairs-n60-s3-1-runtime-vs-chunks-rayon-chunks.png",
                "seed-all-pairs-n60-s3-2-cpu-vs-chunks-rayon-chunks.png",
                "seed-all-pairs-n60-s3-1-runtime-vs-chunks-rayon-chunks-pin-spread.png",
                "seed-all-pairs-n60-s3-2-cpu-vs-chunks-rayon-chunks-pin-spread.png",
                "seed-all-pairs-n60-s3-3-best-rayon-chunks.png",
                "seed-all-pairs-n60-s3-4-speedup.png",
                "seed-all-pairs-n60-s3-5-efficiency.png",
            ]
        );
        assert_eq!(
            p.charts[2].title,
            "Runtime against chunks: rayon-chunks (spread)"
        );
        let ChartKind::Best(best) = &p.charts[4].kind else {
            panic!("chart 3")
        };
        let labels: Vec<&str> = best.speedup.iter().map(|l| l.label.as_str()).collect();
        assert_eq!(labels, ["rayon-chunks", "rayon-chunks (spread)"]);
        assert_eq!(best.runtime[1].points[1].y, 2.1);
        let ChartKind::Speedup { lines, smt } = &p.charts[5].kind else {
            panic!("chart 4")
        };
        assert_eq!(lines.len(), 2);
        assert_eq!(lines[1].pin(), Pin::Spread);
        assert_eq!(*smt, None);
        for c in &p.charts[4..] {
            assert!(
                c.caption
                    .contains("; solid: unpinned (`--pin none`), dashed: pinned `spread`"),
                "{}",
                c.caption
            );
        }
    }

    #[test]
    fn core_counts_on_smt_siblings_are_shaded_in_charts_four_and_five_only() {
        let rows = vec![
            row(StrategyName::Seq, 1, None, 4.0),
            row(StrategyName::RayonIter, 1, None, 4.0),
            row(StrategyName::RayonIter, 2, None, 2.5),
        ];
        let smt = Topology {
            logical_cpus: 2,
            physical_cores: Some(1),
            threads_per_core: Some(2),
            ..Topology::default()
        };
        let p = plan_of(&rows, Some(&smt));
        let band = |k: &ChartKind| match k {
            ChartKind::Speedup { smt, .. } | ChartKind::Efficiency { smt, .. } => smt.clone(),
            _ => None,
        };
        let bands: Vec<Option<SmtBand>> = p.charts.iter().map(|c| band(&c.kind)).collect();
        let shaded = Some(SmtBand {
            physical_cores: 1,
            to: 2,
            cores: vec![2],
        });
        assert_eq!(bands, [None, shaded.clone(), shaded]);
        assert!(p.charts[1].caption.contains(
            "shaded: the core counts past the machine's 1 physical core that put threads \
             on SMT siblings"
        ));
        assert!(p.charts[2].caption.contains("efficiency per physical core"));
        // Without a recorded topology, or one without siblings, nothing is shaded.
        let flat = Topology {
            logical_cpus: 2,
            physical_cores: Some(2),
            ..Topology::default()
        };
        for p in [plan_of(&rows, None), plan_of(&rows, Some(&flat))] {
            assert!(p.charts.iter().all(|c| band(&c.kind).is_none()));
            assert!(p.charts.iter().all(|c| !c.caption.contains("shaded")));
        }
    }

    #[test]
    fn one_core_count_and_no_chunks_skip_their_charts_with_a_reason() {
        let rows = vec![
            row(StrategyName::Seq, 1, None, 4.0),
            row(StrategyName::RayonIter, 2, None, 2.0),
        ];
        let p = plan_of(&rows, None);
        assert!(p.charts.is_empty(), "{:?}", files(&p));
        let notes: Vec<&str> = p.skipped.iter().map(|s| s.note.as_str()).collect();
        assert!(notes[0].contains("no strategy with chunks"), "{notes:?}");
        assert!(notes[1].contains("only 2 cores was measured"), "{notes:?}");
    }

    #[test]
    fn without_a_seq_reference_no_chart_against_cores_is_planned() {
        let rows = vec![
            row(StrategyName::RayonIter, 2, None, 2.0),
            row(StrategyName::RayonIter, 3, None, 1.5),
        ];
        let p = plan_of(&rows, None);
        assert!(p.charts.is_empty());
        assert!(p.skipped[1].note.contains("no usable seq reference"));
    }

    #[test]
    fn both_neighbour_searches_of_a_preset_give_chart_six_across_groups() {
        let mut rows = vec![row(StrategyName::Seq, 1, None, 4.0)];
        let mut grid = row(StrategyName::Seq, 1, None, 1.0);
        grid.neighbors = NeighborMode::Grid;
        rows.push(grid);
        let p = plan_of(&rows, None);
        assert_eq!(files(&p), ["seed-6-neighbors.png"]);
        assert_eq!(p.charts[0].group, None);
        assert!(matches!(&p.charts[0].kind, ChartKind::Neighbors(lines) if lines.len() == 2));
    }
}
