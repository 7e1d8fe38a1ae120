//! The comparison as data: which groups of different sides are the same workload, what each
//! side's best cell is and whether its ranking is resolved, and the charts to draw. A pure
//! function of the sides ([`plan`]); drawing and text come after.
//!
//! Groups match across sides by (preset, neighbours, N) ([`match_groups`]):
//! 1. groups with the same steps too, on two sides or more, match first: their seconds
//!    compare;
//! 2. of the groups left, those with the same (preset, neighbours, N) on two sides or more
//!    match with each side's longest run (most steps): their speedups and efficiencies
//!    compare, their seconds do not, and the report says so;
//! 3. anything else was measured on one side only and is listed as not compared.
//!
//! Every value is each cores value's best cell ([`GroupView::best_per_cores`], the report's
//! one "best cell" rule: the grid's choice, measured again where the side's sweep confirmed
//! it) and its 95 % interval where the sweep recorded one; speedups are over each side's own
//! `seq`, and a machine's fastest strategy is told from the next by their paired rounds. Machines are compared on their unpinned cells (`pin = none`, where the operating
//! system places the threads): placements (`sweep --pin`) are compared within each machine's
//! own report.

use sph_strategies::StrategyName;

use super::sides::{Side, names};
use crate::report::cell::Best;
use crate::report::charts::compare::MachineLines;
use crate::report::plan::{ChartKind, ChartPlan};
use crate::report::select::SeriesKey;
use crate::report::series::{self, Group, Line, Point};
use crate::report::verdict;
use crate::report::verdict::{Entry, Verdict};
use crate::report::view::GroupView;
use sph_harness::results::files::COMPARE_CHART_PREFIX;
use sph_harness::results::key::LabelStyle;
use sph_solver::models::Preset;
use sph_solver::sph::neighbors::NeighborMode;

/// What makes two groups of different sides the same workload: steps may differ.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct MatchKey {
    /// Constants and integration order.
    pub preset: Preset,
    /// Neighbour search.
    pub neighbors: NeighborMode,
    /// Particles.
    pub n: usize,
}

impl MatchKey {
    /// The key of `g`.
    pub fn of(g: &Group) -> MatchKey {
        MatchKey {
            preset: g.preset,
            neighbors: g.neighbors,
            n: g.n,
        }
    }
}

/// One workload measured on two sides or more.
#[derive(Debug, Clone, PartialEq)]
pub struct Matched {
    /// The workload.
    pub key: MatchKey,
    /// (side index, its group), by side.
    pub groups: Vec<(usize, Group)>,
}

impl Matched {
    /// Whether every side ran the same number of steps (then seconds compare too).
    pub fn same_steps(&self) -> bool {
        self.groups.windows(2).all(|w| w[0].1.steps == w[1].1.steps)
    }

    /// The workload in words: the group's label when the steps agree, else the steps per
    /// side (`seed preset, all-pairs, N = 1000; steps differ: A 100, B 1000`).
    pub fn label(&self, sides: &[Side<'_>]) -> String {
        let first = &self.groups[0].1;
        if self.same_steps() {
            return first.label(LabelStyle::Report);
        }
        format!(
            "{} preset, {}, N = {}; steps differ: {}",
            first.preset,
            first.neighbors,
            first.n,
            self.steps_per_side(sides)
        )
    }

    /// `A 100, B 1000`.
    pub fn steps_per_side(&self, sides: &[Side<'_>]) -> String {
        self.groups
            .iter()
            .map(|(i, g)| format!("{} {}", sides[*i].tag, g.steps))
            .collect::<Vec<_>>()
            .join(", ")
    }

    /// A file-name part, `seed-all-pairs-n1000-s100` or, with steps that differ,
    /// `seed-all-pairs-n1000-s100-s1000` (every step count, ascending).
    pub fn slug(&self) -> String {
        let mut steps: Vec<usize> = self.groups.iter().map(|(_, g)| g.steps).collect();
        steps.sort_unstable();
        steps.dedup();
        let steps: Vec<String> = steps.iter().map(|s| format!("s{s}")).collect();
        format!(
            "{}-{}-n{}-{}",
            self.key.preset,
            self.key.neighbors,
            self.key.n,
            steps.join("-")
        )
    }
}

/// How the groups of the sides match (see the module docs).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Matching {
    /// Workloads measured on two sides or more, by first appearance.
    pub matched: Vec<Matched>,
    /// (side index, group) measured on that side only.
    pub alone: Vec<(usize, Group)>,
}

/// Matches `per_side` (each side's groups, in order) across sides; see the module docs.
pub fn match_groups(per_side: &[Vec<Group>]) -> Matching {
    let all: Vec<(usize, Group)> = per_side
        .iter()
        .enumerate()
        .flat_map(|(i, gs)| gs.iter().map(move |g| (i, *g)))
        .collect();
    let mut keys: Vec<MatchKey> = Vec::new();
    for (_, g) in &all {
        if !keys.contains(&MatchKey::of(g)) {
            keys.push(MatchKey::of(g));
        }
    }
    let mut out = Matching::default();
    for key in keys {
        let mut left: Vec<(usize, Group)> = all
            .iter()
            .filter(|(_, g)| MatchKey::of(g) == key)
            .copied()
            .collect();
        // 1. The same steps on two sides or more.
        let mut steps: Vec<usize> = Vec::new();
        for (_, g) in &left {
            if !steps.contains(&g.steps) {
                steps.push(g.steps);
            }
        }
        for s in steps {
            let same: Vec<(usize, Group)> =
                left.iter().filter(|(_, g)| g.steps == s).copied().collect();
            if same.len() > 1 {
                left.retain(|(_, g)| g.steps != s);
                out.matched.push(Matched { key, groups: same });
            }
        }
        // 2. Each side's longest run left, where two sides or more have one.
        let mut longest: Vec<(usize, Group)> = Vec::new();
        for &(i, g) in &left {
            match longest.iter_mut().find(|(j, _)| *j == i) {
                Some(held) if held.1.steps < g.steps => held.1 = g,
                Some(_) => {}
                None => longest.push((i, g)),
            }
        }
        if longest.len() > 1 {
            left.retain(|x| !longest.contains(x));
            longest.sort_by_key(|(i, _)| *i);
            out.matched.push(Matched {
                key,
                groups: longest,
            });
        }
        // 3. The rest: one side only.
        out.alone.extend(left);
    }
    out
}

/// A strategy's best unpinned cell in a group over every cores value: the best cell of each
/// cores value ([`GroupView::best_per_cores`]), and of those the lowest mean, a contended one
/// only where every one is.
pub fn strategy_best(v: &GroupView, s: StrategyName) -> Option<Best> {
    v.best_per_cores(SeriesKey::unpinned(s))
        .into_iter()
        .min_by(|a, b| {
            a.contended
                .cmp(&b.contended)
                .then(a.mean_s.total_cmp(&b.mean_s))
        })
}

/// Every parallel strategy's best cell in `v` over every cores value, in registry order.
pub fn strategy_bests(v: &GroupView) -> Vec<Entry> {
    v.parallel_strategies()
        .into_iter()
        .filter_map(|s| Some((s, Box::new(strategy_best(v, s)?))))
        .collect()
}

/// One machine's fastest strategy in one group: the verdict of the group's findings
/// ([`verdict::verdict`]) on each strategy's best cell, contended ones left out.
#[derive(Debug, Clone, PartialEq)]
pub struct MachineBest {
    /// The side.
    pub side: usize,
    /// Its group.
    pub group: Group,
    /// Every parallel strategy's best cell, in registry order.
    pub entries: Vec<Entry>,
    /// Those measured without contention, lowest mean first ([`verdict::trusted`]).
    pub trusted: Vec<Entry>,
    /// The verdict on `trusted` (`None`: every best cell was contended, or there is none).
    pub verdict: Option<Verdict>,
}

impl MachineBest {
    /// The fastest strategy of the group of `v` on side `side`.
    pub fn of(side: usize, v: &GroupView) -> MachineBest {
        let entries = strategy_bests(v);
        let trusted = verdict::trusted(&entries);
        MachineBest {
            side,
            group: v.group,
            verdict: verdict::verdict(&trusted),
            entries,
            trusted,
        }
    }

    /// The fastest strategy's best cell: the lowest mean measured without contention, or
    /// where every one was contended the lowest mean (shown, not trusted); `None` without a
    /// usable cell.
    pub fn best(&self) -> Option<&Entry> {
        self.trusted.first().or_else(|| {
            self.entries
                .iter()
                .min_by(|a, b| a.1.mean_s.total_cmp(&b.1.mean_s))
        })
    }

    /// Strategies whose best cell was contended and so left out of the ranking.
    pub fn contended_left_out(&self) -> usize {
        self.entries.len() - self.trusted.len()
    }

    /// Whether the fastest is faster than every other strategy by their paired rounds.
    pub fn resolved(&self) -> bool {
        matches!(self.verdict, Some(Verdict::Fastest { .. }))
    }
}

/// One matched workload: each machine's fastest strategy, the charts and the notes on what
/// could not be compared.
#[derive(Debug, Clone)]
pub struct Compared {
    /// The workload and each side's group.
    pub matched: Matched,
    /// Each side's fastest strategy, by side.
    pub best: Vec<MachineBest>,
    /// One chart per strategy with speedups on two machines or more.
    pub charts: Vec<ChartPlan>,
    /// What is not charted, and why.
    pub notes: Vec<String>,
}

/// The whole comparison.
#[derive(Debug, Clone)]
pub struct ComparePlan {
    /// How each side is named beside its tag ([`names`]).
    pub names: Vec<String>,
    /// The matched workloads.
    pub compared: Vec<Compared>,
    /// (side index, group) measured on one side only.
    pub alone: Vec<(usize, Group)>,
    /// Per side, per group in order: every parallel strategy's best cell.
    pub per_side: Vec<Vec<(Group, Vec<Entry>)>>,
    /// Per pair of sides on the same hardware (only `--compare` makes them): how well the
    /// second reproduces the first.
    pub reproduced: Vec<super::reproduce::Reproduced>,
}

/// The comparison of `sides` (see the module docs).
pub fn plan(sides: &[Side<'_>]) -> ComparePlan {
    let names = names(sides);
    let per_side_groups: Vec<Vec<Group>> = sides
        .iter()
        .map(|s| s.views.iter().map(|v| v.group).collect())
        .collect();
    let matching = match_groups(&per_side_groups);
    let compared = matching
        .matched
        .into_iter()
        .map(|m| compare(sides, &names, m))
        .collect();
    let per_side = sides
        .iter()
        .map(|side| {
            side.views
                .iter()
                .map(|v| (v.group, strategy_bests(v)))
                .collect()
        })
        .collect();
    ComparePlan {
        names,
        compared,
        alone: matching.alone,
        per_side,
        reproduced: super::reproduce::pairs(sides),
    }
}

/// The best cells, charts and notes of one matched workload.
fn compare(sides: &[Side<'_>], names: &[String], matched: Matched) -> Compared {
    let view = |i: usize, g: &Group| sides[i].view(g).expect("a matched group is measured");
    let best = matched
        .groups
        .iter()
        .map(|(i, g)| MachineBest::of(*i, view(*i, g)))
        .collect();
    let mut notes = Vec::new();
    // Per side: its speedup lines in this workload (none without a usable seq).
    let mut speedups: Vec<(usize, Vec<Line>)> = Vec::new();
    let mut strategies: Vec<StrategyName> = Vec::new();
    for (i, g) in &matched.groups {
        let v = view(*i, g);
        if v.reference().is_none() {
            notes.push(format!(
                "{} has no usable `seq` reference here: no speedup or efficiency from it.",
                sides[*i].tag
            ));
            speedups.push((*i, Vec::new()));
        } else {
            speedups.push((*i, series::speedup_lines(&v.series_bests())));
        }
        for s in v.parallel_strategies() {
            if !strategies.contains(&s) {
                strategies.push(s);
            }
        }
    }
    let subtitle = matched.label(sides);
    let mut charts = Vec::new();
    for s in strategies {
        let lines: Vec<MachineLines> = speedups
            .iter()
            .filter_map(|(i, lines)| {
                let speedup = lines
                    .iter()
                    .find(|l| l.series == Some(SeriesKey::unpinned(s)))?;
                Some(MachineLines {
                    side: *i,
                    legend: wrap(&format!("{}: {}", sides[*i].tag, names[*i]), LEGEND_CHARS),
                    speedup: speedup.clone(),
                    efficiency: efficiency_of(speedup),
                })
            })
            .collect();
        match lines.as_slice() {
            [] => notes.push(format!("{s}: no speedup on any machine (no usable cell).")),
            [one] => notes.push(format!(
                "{s}: speedups on {} only: nothing to compare, no chart.",
                sides[one.side].tag
            )),
            _ => charts.push(ChartPlan {
                file: format!("{COMPARE_CHART_PREFIX}{}-{s}.png", matched.slug()),
                group: None,
                title: format!("Speedup and efficiency on each machine: {s}"),
                caption: format!(
                    "{s}: best speedup over each machine's own seq (above; bars: 95 % \
                     confidence interval of the best cell) and efficiency S / p (below; the \
                     same interval over p) against cores, one line per machine; {subtitle}."
                ),
                subtitle: subtitle.clone(),
                kind: ChartKind::Machines { strategy: s, lines },
            }),
        }
    }
    Compared {
        matched,
        best,
        charts,
        notes,
    }
}

/// Characters per legend line that fit the charts' legend panel.
const LEGEND_CHARS: usize = 24;

/// `text` broken at spaces into lines of at most `width` characters (a longer word stands on
/// a line of its own).
pub fn wrap(text: &str, width: usize) -> String {
    let mut lines: Vec<String> = Vec::new();
    for word in text.split_whitespace() {
        match lines.last_mut() {
            Some(line) if line.chars().count() + 1 + word.chars().count() <= width => {
                line.push(' ');
                line.push_str(word);
            }
            _ => lines.push(word.to_owned()),
        }
    }
    lines.join("\n")
}

/// Efficiency against cores from a speedup line: each value and its interval over the cores.
pub fn efficiency_of(speedup: &Line) -> Line {
    Line {
        points: speedup
            .points
            .iter()
            .map(|p| Point {
                y: p.y / p.x,
                lo: p.lo / p.x,
                hi: p.hi / p.x,
                ..*p
            })
            .collect(),
        ..speedup.clone()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::report::compare::sides::{SideRule, sides};
    use crate::report::verdict::Unknown;
    use crate::report::view::tests::{measured, of_rows, with_trials};
    use sph_harness::results::fixtures::row;
    use sph_harness::results::fixtures::sweep_on;
    use sph_harness::results::rows::{Phase, SummaryRow, TrialRow};
    use sph_harness::topology::Pin;

    fn group(n: usize, steps: usize) -> Group {
        Group {
            preset: Preset::Seed,
            neighbors: NeighborMode::AllPairs,
            n,
            steps,
        }
    }

    /// seq at 4 s; rayon-chunks and rayon-iter at 1 and 2 cores, each `mean` at 2 cores.
    fn study(chunks_2: f64, iter_2: f64, steps: usize) -> Vec<SummaryRow> {
        [
            row(StrategyName::Seq, 1, None, 4.0),
            row(StrategyName::RayonChunks, 1, Some(5), 4.1),
            row(StrategyName::RayonChunks, 2, Some(5), chunks_2),
            row(StrategyName::RayonIter, 1, None, 4.2),
            row(StrategyName::RayonIter, 2, None, iter_2),
        ]
        .into_iter()
        .map(|r| SummaryRow { steps, ..r })
        .collect()
    }

    #[test]
    fn the_same_steps_match_first_then_each_sides_longest_run_and_the_rest_stands_alone() {
        let a = vec![group(1000, 1000), group(1000, 100), group(60, 3)];
        let b = vec![group(1000, 100), group(1000, 500), group(120, 3)];
        let m = match_groups(&[a, b]);
        let matched: Vec<Vec<(usize, usize)>> = m
            .matched
            .iter()
            .map(|x| x.groups.iter().map(|(i, g)| (*i, g.steps)).collect())
            .collect();
        assert_eq!(
            matched,
            [vec![(0, 100), (1, 100)], vec![(0, 1000), (1, 500)]]
        );
        assert!(m.matched[0].same_steps() && !m.matched[1].same_steps());
        assert_eq!(m.matched[1].slug(), "seed-all-pairs-n1000-s500-s1000");
        assert_eq!(m.alone, [(0, group(60, 3)), (1, group(120, 3))]);
    }

    #[test]
    fn a_side_with_two_runs_of_a_workload_left_offers_its_longest_and_the_other_stays_alone() {
        let a = vec![group(1000, 100), group(1000, 300)];
        let b = vec![group(1000, 200)];
        let m = match_groups(&[a, b]);
        assert_eq!(m.matched.len(), 1);
        assert_eq!(
            m.matched[0].groups,
            [(0, group(1000, 300)), (1, group(1000, 200))]
        );
        assert_eq!(m.alone, [(0, group(1000, 100))]);
    }

    #[test]
    fn a_strategys_best_cell_is_the_fastest_over_every_cores_value_contended_last() {
        let rows = study(2.2, 2.4, 3);
        let b = strategy_best(&of_rows(rows.clone()), StrategyName::RayonChunks).unwrap();
        assert_eq!((b.cores, b.chunks, b.mean_s), (2, Some(5), 2.2));
        let mut contended = rows;
        contended[2].contended = Some(true);
        let b = strategy_best(&of_rows(contended), StrategyName::RayonChunks).unwrap();
        assert_eq!((b.cores, b.mean_s), (1, 4.1));
    }

    /// seq and, at 2 cores, rayon-chunks and rayon-iter with these walls per round.
    fn paired(chunks: &[f64], iter: &[f64]) -> (Vec<SummaryRow>, Vec<TrialRow>) {
        measured(
            &[
                (StrategyName::Seq, 1, None, Pin::None, &[4.0, 4.4, 3.6]),
                (StrategyName::RayonChunks, 2, Some(5), Pin::None, chunks),
                (StrategyName::RayonIter, 2, None, Pin::None, iter),
            ],
            Phase::Grid,
        )
    }

    #[test]
    fn a_machine_best_is_resolved_only_where_the_paired_rounds_resolve_it() {
        let (rows, trials) = paired(&[2.0, 2.2, 1.8], &[2.4, 2.64, 2.16]);
        let b = MachineBest::of(0, &with_trials(rows, trials));
        assert_eq!(b.best().unwrap().0, StrategyName::RayonChunks);
        assert!(b.resolved());
        assert!(
            matches!(&b.verdict, Some(Verdict::Fastest { runner_up, by, .. }) if runner_up.0 == StrategyName::RayonIter && (by.value - 1.2).abs() < 1e-12)
        );
        // Rounds that disagree: not distinguishable.
        let (rows, trials) = paired(&[2.0, 2.4, 1.6], &[2.1, 2.2, 1.8]);
        let b = MachineBest::of(0, &with_trials(rows, trials));
        assert!(!b.resolved());
        assert!(matches!(&b.verdict, Some(Verdict::Tied { tied, .. }) if tied.len() == 2));
        // Two rounds: no interval.
        let (rows, trials) = paired(&[2.0, 2.2], &[2.4, 2.64]);
        let b = MachineBest::of(0, &with_trials(rows, trials));
        assert!(matches!(
            &b.verdict,
            Some(Verdict::Unknown {
                why: Unknown::Rounds(2),
                ..
            })
        ));
        let (mut rows, trials) = paired(&[2.0, 2.2, 1.8], &[2.4, 2.64, 2.16]);
        for r in &mut rows {
            r.contended = Some(true);
        }
        let b = MachineBest::of(0, &with_trials(rows, trials));
        assert_eq!((b.verdict.clone(), b.contended_left_out()), (None, 2));
        assert_eq!(b.best().unwrap().1.mean_s, 2.0);
    }

    #[test]
    fn a_workload_on_two_machines_gets_one_chart_per_strategy_with_a_line_per_machine() {
        let sweeps = [
            sweep_on("a", "Xeon", 2, study(2.2, 2.4, 3)),
            sweep_on("b", "EPYC", 16, study(1.1, 1.0, 5)),
        ];
        let sides = sides(&sweeps, SideRule::ByMachine);
        let p = plan(&sides);
        assert_eq!(p.compared.len(), 1);
        let c = &p.compared[0];
        assert_eq!(
            c.matched.label(&sides),
            "seed preset, all-pairs, N = 60; steps differ: A 3, B 5"
        );
        let files: Vec<&str> = c.charts.iter().map(|c| c.file.as_str()).collect();
        assert_eq!(
            files,
            [
                "compare-seed-all-pairs-n60-s3-s5-rayon-chunks.png",
                "compare-seed-all-pairs-n60-s3-s5-rayon-iter.png"
            ]
        );
        let ChartKind::Machines { lines, .. } = &c.charts[0].kind else {
            panic!("a comparison's chart has a line per machine");
        };
        assert_eq!(lines.len(), 2);
        assert_eq!(lines[1].legend, "B: EPYC, 16 hardware\nthreads");
        let at_two = lines[1].speedup.points[1];
        assert_eq!((at_two.x, at_two.y), (2.0, 4.0 / 1.1));
        assert_eq!(lines[1].efficiency.points[1].y, 4.0 / 1.1 / 2.0);
        let bests: Vec<StrategyName> = c.best.iter().map(|b| b.best().unwrap().0).collect();
        assert_eq!(bests, [StrategyName::RayonChunks, StrategyName::RayonIter]);
        assert!(c.notes.is_empty(), "{:?}", c.notes);
        assert_eq!(p.per_side[1][0].1.len(), 2);
    }

    #[test]
    fn a_strategy_on_one_machine_only_or_a_side_without_seq_is_noted_not_charted() {
        let mut b_rows = study(1.1, 1.0, 3);
        b_rows.retain(|r| r.strategy != StrategyName::RayonIter);
        let mut c_rows = study(1.1, 1.0, 3);
        c_rows.retain(|r| r.strategy != StrategyName::Seq);
        let sweeps = [
            sweep_on("a", "Xeon", 2, study(2.2, 2.4, 3)),
            sweep_on("b", "EPYC", 16, b_rows),
            sweep_on("c", "Arm", 8, c_rows),
        ];
        let sides = sides(&sweeps, SideRule::ByMachine);
        let c = &plan(&sides).compared[0];
        assert_eq!(c.charts.len(), 1);
        assert_eq!(
            c.notes[0],
            "C has no usable `seq` reference here: no speedup or efficiency from it."
        );
        assert_eq!(
            c.notes[1],
            "rayon-iter: speedups on A only: nothing to compare, no chart."
        );
    }

    #[test]
    fn legend_text_wraps_at_spaces() {
        assert_eq!(
            wrap("A: Intel(R) Xeon(R) Processor, 2 hardware threads", 24),
            "A: Intel(R) Xeon(R)\nProcessor, 2 hardware\nthreads"
        );
        assert_eq!(wrap("short", 24), "short");
    }
}
