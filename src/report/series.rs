//! Pure functions from summary rows to what the charts and the report show: groups, lines of
//! points, the best cell per core count, speedup spreads, the Karp–Flatt serial fraction.
//!
//! Only cells with `status = ok` and a mean enter a series; failed cells are listed by the
//! report instead. Times are seconds.
//!
//! A series is one strategy at one placement ([`SeriesKey`]): pinned and unpinned cells of a
//! strategy (`sweep --pin`) are never pooled into one line, one best cell or one table row.

use std::collections::BTreeSet;
use std::fmt;

use crate::results::stats::Interval;

use sph_strategies::StrategyName;

pub use crate::results::key::Group;
use crate::results::rows::{Contended, SummaryRow, fastest};
use crate::sph::neighbors::NeighborMode;
use crate::sph::params::Preset;
use crate::topology::{Pin, Topology};

/// The groups of `rows`, in the order they first appear.
pub fn groups(rows: &[SummaryRow]) -> Vec<Group> {
    let mut out: Vec<Group> = Vec::new();
    for r in rows {
        let g = r.group();
        if !out.contains(&g) {
            out.push(g);
        }
    }
    out
}

/// The rows of `group` that may be used.
pub fn ok_rows<'a>(rows: &'a [SummaryRow], group: &Group) -> Vec<&'a SummaryRow> {
    rows.iter()
        .filter(|r| r.group() == *group && r.is_usable())
        .collect()
}

/// The strategies of `group` in the order they first appear (the registry order of the plan).
pub fn strategies(rows: &[SummaryRow], group: &Group) -> Vec<StrategyName> {
    let mut out: Vec<StrategyName> = Vec::new();
    for r in rows.iter().filter(|r| r.group() == *group) {
        if !out.contains(&r.strategy) {
            out.push(r.strategy);
        }
    }
    out
}

/// One strategy's cells at one placement: what a line of the charts and a row of the tables
/// are drawn from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct SeriesKey {
    /// The strategy.
    pub strategy: StrategyName,
    /// Where its threads ran (`pin`).
    pub pin: Pin,
}

impl SeriesKey {
    /// `strategy` at placement `pin`.
    pub fn new(strategy: StrategyName, pin: Pin) -> SeriesKey {
        SeriesKey { strategy, pin }
    }

    /// `strategy`'s unpinned cells (`pin = none`).
    pub fn unpinned(strategy: StrategyName) -> SeriesKey {
        SeriesKey::new(strategy, Pin::None)
    }

    /// Whether a row belongs to the series (any group).
    fn holds(&self, r: &SummaryRow) -> bool {
        r.strategy == self.strategy && r.pin == self.pin
    }
}

/// `rayon-chunks` unpinned, `rayon-chunks (spread)` pinned: legends, tables and findings.
impl fmt::Display for SeriesKey {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.pin {
            Pin::None => write!(f, "{}", self.strategy),
            pin => write!(f, "{} ({pin})", self.strategy),
        }
    }
}

/// The placements `strategy` was measured at in `group`, `none` first, then `compact`,
/// `spread`.
pub fn pins(rows: &[SummaryRow], group: &Group, strategy: StrategyName) -> Vec<Pin> {
    let set: BTreeSet<Pin> = rows
        .iter()
        .filter(|r| r.group() == *group && r.strategy == strategy)
        .map(|r| r.pin)
        .collect();
    set.into_iter().collect()
}

/// The series of `group` (every strategy but `seq`): the strategies in the order they first
/// appear, each at its placements in the order of [`pins`].
pub fn series(rows: &[SummaryRow], group: &Group) -> Vec<SeriesKey> {
    strategies(rows, group)
        .into_iter()
        .filter(|&s| s != StrategyName::Seq)
        .flat_map(|s| {
            pins(rows, group, s)
                .into_iter()
                .map(move |p| SeriesKey::new(s, p))
        })
        .collect()
}

/// Whether some cell of `group` was pinned (`seq` never is): the report then names each
/// cell's placement.
pub fn is_pinned(rows: &[SummaryRow], group: &Group) -> bool {
    rows.iter()
        .any(|r| r.group() == *group && r.pin != Pin::None)
}

/// Whether `strategy` has cells with a chunks value in `group`.
pub fn is_chunked(rows: &[SummaryRow], group: &Group, strategy: StrategyName) -> bool {
    rows.iter()
        .any(|r| r.group() == *group && r.strategy == strategy && r.chunks.is_some())
}

/// The distinct core counts of the usable cells of `group` (any strategy but `seq`).
pub fn cores(rows: &[SummaryRow], group: &Group) -> Vec<usize> {
    let set: BTreeSet<usize> = ok_rows(rows, group)
        .iter()
        .filter(|r| !r.is_reference())
        .map(|r| r.cores)
        .collect();
    set.into_iter().collect()
}

/// The group's reference: `seq`'s mean seconds.
pub fn seq_mean(rows: &[SummaryRow], group: &Group) -> Option<f64> {
    ok_rows(rows, group)
        .iter()
        .find(|r| r.is_reference())
        .and_then(|r| r.mean_s)
}

/// A point with its uncertainty: `y` the value, `lo..hi` its 95 % confidence interval
/// (equal to `y` when unknown).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Point {
    /// Abscissa (chunks, cores or N).
    pub x: f64,
    /// Value.
    pub y: f64,
    /// Lower end of the spread.
    pub lo: f64,
    /// Upper end of the spread.
    pub hi: f64,
    /// Whether the cell used more threads than the machine has.
    pub oversubscribed: bool,
    /// Whether other work used the machine while the cell was measured (or a trial ran
    /// passes alone: its threads got less CPU time than its chunks had work for).
    pub contended: bool,
}

impl Point {
    /// A point without uncertainty or flags (a reference value).
    pub fn exact(x: f64, y: f64) -> Point {
        Point {
            x,
            y,
            lo: y,
            hi: y,
            oversubscribed: false,
            contended: false,
        }
    }
}

/// A labelled line of points, sorted by x.
#[derive(Debug, Clone, PartialEq)]
pub struct Line {
    /// Legend text.
    pub label: String,
    /// Points by increasing x.
    pub points: Vec<Point>,
    /// The strategy and placement it shows, where it shows one (its colour and line style);
    /// `None` for lines of core counts or neighbour searches.
    pub series: Option<SeriesKey>,
}

impl Line {
    /// A line that shows no series (see [`Line::series`]).
    pub fn new(label: impl Into<String>, points: Vec<Point>) -> Line {
        Line {
            label: label.into(),
            points,
            series: None,
        }
    }

    /// The placement of its series (`none` for a line without one): how it is dashed.
    pub fn pin(&self) -> Pin {
        self.series.map_or(Pin::None, |k| k.pin)
    }

    /// The index of the lowest point (the first one on ties).
    pub fn min_index(&self) -> Option<usize> {
        (0..self.points.len()).min_by(|&a, &b| self.points[a].y.total_cmp(&self.points[b].y))
    }

    /// Whether any point is oversubscribed.
    pub fn any_oversubscribed(&self) -> bool {
        self.points.iter().any(|p| p.oversubscribed)
    }
}

/// What a chunks chart shows on its y axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Metric {
    /// Mean wall seconds (spread: fastest to slowest trial).
    Wall,
    /// Mean CPU seconds, user + system.
    Cpu,
}

/// One line per core count: `metric` against chunks, for the series `key` of a chunked
/// strategy in `group` (Figures 7 and 8 of the paper).
pub fn chunk_lines(
    rows: &[SummaryRow],
    group: &Group,
    key: SeriesKey,
    metric: Metric,
) -> Vec<Line> {
    let ok = ok_rows(rows, group);
    let mut out = Vec::new();
    for c in cores(rows, group) {
        let mut points: Vec<Point> = ok
            .iter()
            .filter(|r| key.holds(r) && r.cores == c)
            .filter_map(|r| {
                let x = r.chunks? as f64;
                let (y, lo, hi) = match metric {
                    Metric::Wall => {
                        let y = r.mean_s?;
                        (
                            y,
                            r.mean_ci_low_s.unwrap_or(y),
                            r.mean_ci_high_s.unwrap_or(y),
                        )
                    }
                    Metric::Cpu => {
                        let y = r.cpu_mean_s?;
                        (y, y, y)
                    }
                };
                Some(Point {
                    x,
                    y,
                    lo,
                    hi,
                    oversubscribed: r.oversubscribed,
                    contended: r.contended == Some(true),
                })
            })
            .collect();
        if points.is_empty() {
            continue;
        }
        points.sort_by(|a, b| a.x.total_cmp(&b.x));
        out.push(Line::new(cores_label(c), points));
    }
    out
}

/// `1 core`, `3 cores`.
pub fn cores_label(c: usize) -> String {
    format!("{c} {}", if c == 1 { "core" } else { "cores" })
}

/// The fastest cell of a strategy at one core count.
#[derive(Debug, Clone, PartialEq)]
pub struct Best {
    /// Worker threads.
    pub cores: usize,
    /// Chunks of the fastest cell (`None` for strategies without chunks).
    pub chunks: Option<usize>,
    /// Where its threads ran.
    pub pin: Pin,
    /// Mean wall seconds.
    pub mean_s: f64,
    /// Sample standard deviation (`None` for one trial).
    pub stddev_s: Option<f64>,
    /// Fastest trial.
    pub min_s: f64,
    /// Slowest trial.
    pub max_s: f64,
    /// The group's `seq` mean over this mean.
    pub speedup: Option<f64>,
    /// Speedup over cores.
    pub efficiency: Option<f64>,
    /// More threads than the machine has.
    pub oversubscribed: bool,
    /// 95 % interval of the mean seconds (`None` for one trial or an older sweep).
    pub mean_ci: Option<Interval>,
    /// 95 % interval of the speedup.
    pub speedup_ci: Option<Interval>,
    /// Other work used the machine while it was measured.
    pub contended: bool,
}

impl Best {
    /// A usable cell's numbers (`None` without a mean).
    pub fn of(r: &SummaryRow) -> Option<Best> {
        let mean_s = r.mean_s?;
        Some(Best {
            cores: r.cores,
            chunks: r.chunks,
            pin: r.pin,
            mean_s,
            stddev_s: r.stddev_s,
            min_s: r.min_s.unwrap_or(mean_s),
            max_s: r.max_s.unwrap_or(mean_s),
            speedup: r.speedup,
            efficiency: r.efficiency,
            oversubscribed: r.oversubscribed,
            mean_ci: interval(r.mean_ci_low_s, r.mean_ci_high_s),
            speedup_ci: interval(r.speedup_ci_low, r.speedup_ci_high),
            contended: r.contended == Some(true),
        })
    }

    /// The Karp–Flatt serial fraction at this cell (see [`karp_flatt`]).
    pub fn serial_fraction(&self) -> Option<f64> {
        karp_flatt(self.speedup?, self.cores)
    }
}

/// The fastest usable cell of the series `key` in `group` at each core count, by cores.
pub fn best_per_cores(rows: &[SummaryRow], group: &Group, key: SeriesKey) -> Vec<Best> {
    let ok = ok_rows(rows, group);
    let mut set: BTreeSet<usize> = BTreeSet::new();
    for r in ok.iter().filter(|r| key.holds(r)) {
        set.insert(r.cores);
    }
    set.into_iter()
        .filter_map(|c| {
            // The fastest trustworthy cell; a contended one only when all of them are.
            let r = fastest(
                ok.iter().copied().filter(|r| key.holds(r) && r.cores == c),
                Contended::LastResort,
            )?;
            Best::of(r)
        })
        .collect()
}

/// An interval from its two ends, if both are known.
pub fn interval(low: Option<f64>, high: Option<f64>) -> Option<Interval> {
    Some(Interval {
        low: low?,
        high: high?,
    })
}

/// The Karp–Flatt experimentally determined serial fraction
/// `e = (1/S − 1/p) / (1 − 1/p)` for speedup `S` on `p` processors; undefined for `p = 1`.
pub fn karp_flatt(speedup: f64, p: usize) -> Option<f64> {
    if p < 2 || !(speedup.is_finite() && speedup > 0.0) {
        return None;
    }
    let p = p as f64;
    Some((1.0 / speedup - 1.0 / p) / (1.0 - 1.0 / p))
}

/// Best lines per series of `group` ([`series`]: every strategy but `seq`, at each of its
/// placements): speedup against cores, with the best cell's 95 % interval of the speedup.
pub fn speedup_lines(rows: &[SummaryRow], group: &Group) -> Vec<Line> {
    let Some(seq) = seq_mean(rows, group) else {
        return Vec::new();
    };
    series(rows, group)
        .into_iter()
        .filter_map(|key| {
            let points: Vec<Point> = best_per_cores(rows, group, key)
                .iter()
                .map(|b| {
                    let y = seq / b.mean_s;
                    Point {
                        x: b.cores as f64,
                        y,
                        lo: b.speedup_ci.map_or(y, |i| i.low),
                        hi: b.speedup_ci.map_or(y, |i| i.high),
                        oversubscribed: b.oversubscribed,
                        contended: b.contended,
                    }
                })
                .collect();
            (!points.is_empty()).then_some(Line {
                label: key.to_string(),
                points,
                series: Some(key),
            })
        })
        .collect()
}

/// Best runtime against cores for one series (bars: 95 % interval of the mean).
pub fn runtime_line(best: &[Best], key: SeriesKey) -> Line {
    Line {
        label: key.to_string(),
        series: Some(key),
        points: best
            .iter()
            .map(|b| Point {
                x: b.cores as f64,
                y: b.mean_s,
                lo: b.mean_ci.map_or(b.mean_s, |i| i.low),
                hi: b.mean_ci.map_or(b.mean_s, |i| i.high),
                oversubscribed: b.oversubscribed,
                contended: b.contended,
            })
            .collect(),
    }
}

/// Per strategy, efficiency against cores (all core counts) and the Karp–Flatt fraction
/// against cores (only where it means something: at least 2 cores and a speedup above 1).
pub fn efficiency_lines(rows: &[SummaryRow], group: &Group) -> (Vec<Line>, Vec<Line>) {
    let mut eff = Vec::new();
    let mut kf = Vec::new();
    for line in speedup_lines(rows, group) {
        let point = |p: &Point, y: f64| Point {
            x: p.x,
            y,
            lo: y,
            hi: y,
            oversubscribed: p.oversubscribed,
            contended: p.contended,
        };
        eff.push(Line {
            label: line.label.clone(),
            points: line.points.iter().map(|p| point(p, p.y / p.x)).collect(),
            series: line.series,
        });
        let k: Vec<Point> = line
            .points
            .iter()
            .filter(|p| p.y > 1.0)
            .filter_map(|p| Some(point(p, karp_flatt(p.y, p.x as usize)?)))
            .collect();
        if !k.is_empty() {
            kf.push(Line {
                label: line.label,
                points: k,
                series: line.series,
            });
        }
    }
    (eff, kf)
}

/// For chart 6: per neighbour mode of `preset`, seconds per step against N for `seq` and for
/// the fastest cell of any other strategy. `None` unless both modes are present.
// Over ~60 lines on purpose: one pass per (mode, steps) pair builds both lines; split, the two
// would have to share the per-step point closure.
pub fn neighbor_lines(rows: &[SummaryRow], preset: Preset) -> Option<Vec<Line>> {
    let gs: Vec<Group> = groups(rows)
        .into_iter()
        .filter(|g| g.preset == preset)
        .collect();
    let modes: BTreeSet<NeighborMode> = gs.iter().map(|g| g.neighbors).collect();
    if modes.len() < 2 {
        return None;
    }
    let mut lines = Vec::new();
    let steps: BTreeSet<usize> = gs.iter().map(|g| g.steps).collect();
    for (mode, run_steps) in modes
        .iter()
        .flat_map(|m| steps.iter().map(move |s| (*m, *s)))
    {
        let mut seq_points = Vec::new();
        let mut best_points = Vec::new();
        for g in gs
            .iter()
            .filter(|g| g.neighbors == mode && g.steps == run_steps)
        {
            let ok = ok_rows(rows, g);
            let per_step = |r: &SummaryRow| -> Option<Point> {
                let s = g.steps as f64;
                let y = r.mean_s? / s;
                Some(Point {
                    x: g.n as f64,
                    y,
                    lo: r.mean_ci_low_s.map_or(y, |v| v / s),
                    hi: r.mean_ci_high_s.map_or(y, |v| v / s),
                    oversubscribed: r.oversubscribed,
                    contended: r.contended == Some(true),
                })
            };
            if let Some(p) = ok
                .iter()
                .find(|r| r.is_reference())
                .and_then(|r| per_step(r))
            {
                seq_points.push(p);
            }
            let best = fastest(
                ok.iter().copied().filter(|r| !r.is_reference()),
                Contended::Compete,
            );
            if let Some(p) = best.and_then(per_step) {
                best_points.push(p);
            }
        }
        let each = if steps.len() > 1 {
            format!(", {run_steps} steps")
        } else {
            String::new()
        };
        for (label, mut points) in [
            (format!("{mode}, seq (1 core){each}"), seq_points),
            (format!("{mode}, fastest parallel cell{each}"), best_points),
        ] {
            points.sort_by(|a, b| a.x.total_cmp(&b.x));
            if !points.is_empty() {
                lines.push(Line::new(label, points));
            }
        }
    }
    Some(lines)
}

/// The presets of `rows`, in order of appearance.
pub fn presets(rows: &[SummaryRow]) -> Vec<Preset> {
    let mut out: Vec<Preset> = Vec::new();
    for g in groups(rows) {
        if !out.contains(&g.preset) {
            out.push(g.preset);
        }
    }
    out
}

/// One cell of a chunks line: (chunks, mean seconds, stddev seconds).
pub type ChunkCell = (usize, f64, f64);

/// For a chunks line: the smallest chunk count from which no larger count improves the mean by
/// more than the spread (the larger of the two cells' stddevs; 0 when unknown). `None` for an
/// empty line.
pub fn chunking_stops_paying(line: &[ChunkCell]) -> Option<usize> {
    // line: (chunks, mean, stddev), sorted by chunks.
    (0..line.len())
        .find(|&i| {
            let (_, t, s) = line[i];
            line[i + 1..].iter().all(|&(_, u, su)| t - u <= s.max(su))
        })
        .map(|i| line[i].0)
}

/// The chunks lines of a series in a form for [`chunking_stops_paying`]: per core count,
/// `(cores, [(chunks, mean, stddev)])`.
pub fn chunk_table(
    rows: &[SummaryRow],
    group: &Group,
    key: SeriesKey,
) -> Vec<(usize, Vec<ChunkCell>)> {
    let ok = ok_rows(rows, group);
    cores(rows, group)
        .into_iter()
        .map(|c| {
            let mut v: Vec<ChunkCell> = ok
                .iter()
                .filter(|r| key.holds(r) && r.cores == c)
                .filter(|r| r.contended != Some(true))
                .filter_map(|r| Some((r.chunks?, r.mean_s?, r.stddev_s.unwrap_or(0.0))))
                .collect();
            v.sort_by_key(|t| t.0);
            (c, v)
        })
        .filter(|(_, v)| !v.is_empty())
        .collect()
}

/// The core counts of a group whose threads outnumber the machine's physical cores but not
/// its logical CPUs ([`Topology::is_smt`]): there, threads share physical cores as SMT
/// siblings. The charts shade the core counts past `physical_cores` up to `to`; the tables
/// add the efficiency per physical core.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SmtBand {
    /// The machine's physical cores (of the CPUs the sweep could use): the band starts here.
    pub physical_cores: usize,
    /// The band's end: the most cores measured, at most the logical CPUs.
    pub to: usize,
    /// The measured core counts in the band, ascending.
    pub cores: Vec<usize>,
}

impl SmtBand {
    /// Speedup `s` at `cores` over the physical cores those threads had at most:
    /// `S / min(cores, physical cores)`, equal to `S / cores` below the band.
    pub fn physical_efficiency(&self, speedup: f64, cores: usize) -> f64 {
        speedup / cores.min(self.physical_cores).max(1) as f64
    }
}

/// Where `topology` says some of the measured `cores` put threads on SMT siblings, the band
/// that shows them; `None` where none does or the physical cores are unknown.
pub fn smt_band(topology: &Topology, cores: &[usize]) -> Option<SmtBand> {
    let physical_cores = topology.physical_cores?;
    let smt: Vec<usize> = cores
        .iter()
        .copied()
        .filter(|&c| topology.is_smt(c) == Some(true))
        .collect::<BTreeSet<usize>>()
        .into_iter()
        .collect();
    let last = *smt.last()?;
    let most = cores.iter().copied().max().unwrap_or(last);
    Some(SmtBand {
        physical_cores,
        to: most.min(topology.logical_cpus).max(last),
        cores: smt,
    })
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::results::rows::Status;
    use crate::results::rows::tests::row;

    fn sample() -> Vec<SummaryRow> {
        let mut failed = row(StrategyName::RayonChunks, 2, Some(20), 0.1);
        failed.status = Status::Failed;
        failed.mean_s = None;
        vec![
            row(StrategyName::Seq, 1, None, 4.0),
            row(StrategyName::RayonChunks, 1, Some(10), 4.2),
            row(StrategyName::RayonChunks, 1, Some(5), 4.1),
            row(StrategyName::RayonChunks, 2, Some(5), 2.5),
            row(StrategyName::RayonChunks, 2, Some(10), 2.2),
            failed,
            row(StrategyName::RayonIter, 2, None, 2.0),
            row(StrategyName::RayonIter, 3, None, 2.4),
        ]
    }

    #[test]
    fn karp_flatt_is_zero_for_ideal_speedup_and_one_for_none() {
        assert_eq!(karp_flatt(4.0, 4), Some(0.0));
        assert_eq!(karp_flatt(1.0, 4), Some(1.0));
        assert_eq!(karp_flatt(2.0, 1), None);
        let e = karp_flatt(5.13, 6).unwrap();
        assert!((e - (1.0 / 5.13 - 1.0 / 6.0) / (1.0 - 1.0 / 6.0)).abs() < 1e-15);
    }

    #[test]
    fn the_best_cell_per_cores_is_the_fastest_usable_one() {
        let rows = sample();
        let g = rows[0].group();
        let best = best_per_cores(&rows, &g, SeriesKey::unpinned(StrategyName::RayonChunks));
        assert_eq!(best.len(), 2);
        assert_eq!(
            (best[0].cores, best[0].chunks, best[0].mean_s),
            (1, Some(5), 4.1)
        );
        // The failed cell at 20 chunks (0.1 s) is ignored.
        assert_eq!(
            (best[1].cores, best[1].chunks, best[1].mean_s),
            (2, Some(10), 2.2)
        );
    }

    #[test]
    fn chunk_lines_have_one_line_per_cores_sorted_by_chunks_with_their_minimum() {
        let rows = sample();
        let g = rows[0].group();
        let lines = chunk_lines(
            &rows,
            &g,
            SeriesKey::unpinned(StrategyName::RayonChunks),
            Metric::Wall,
        );
        assert_eq!(lines.len(), 2);
        assert_eq!(lines[0].label, "1 core");
        assert_eq!(lines[0].points[0].x, 5.0);
        assert_eq!(lines[0].min_index(), Some(0));
        assert_eq!(lines[1].min_index(), Some(1));
        let cpu = chunk_lines(
            &rows,
            &g,
            SeriesKey::unpinned(StrategyName::RayonChunks),
            Metric::Cpu,
        );
        assert_eq!(cpu[1].points[1].y, 4.4);
    }

    #[test]
    fn speedup_lines_skip_seq_and_carry_the_trial_spread_and_oversubscription() {
        let rows = sample();
        let g = rows[0].group();
        let lines = speedup_lines(&rows, &g);
        let labels: Vec<&str> = lines.iter().map(|l| l.label.as_str()).collect();
        assert_eq!(labels, ["rayon-chunks", "rayon-iter"]);
        let p = lines[1].points[1];
        assert_eq!((p.x, p.y), (3.0, 4.0 / 2.4));
        assert!(p.oversubscribed);
        assert!(p.lo < p.y && p.y < p.hi);
        let (eff, kf) = efficiency_lines(&rows, &g);
        assert_eq!(eff[1].points[0].y, 1.0);
        assert_eq!(kf[0].points.len(), 1, "no Karp–Flatt value at 1 core");
    }

    #[test]
    fn chunking_stops_paying_where_no_larger_count_beats_the_spread() {
        let line = [
            (2, 10.0, 0.1),
            (5, 8.0, 0.1),
            (10, 7.95, 0.1),
            (20, 7.9, 0.1),
        ];
        assert_eq!(chunking_stops_paying(&line), Some(5));
        assert_eq!(chunking_stops_paying(&[(2, 1.0, 0.0)]), Some(2));
        assert_eq!(chunking_stops_paying(&[]), None);
    }

    #[test]
    fn chart_six_needs_both_neighbour_modes() {
        let rows = sample();
        assert!(neighbor_lines(&rows, Preset::Seed).is_none());
        let mut both = rows.clone();
        for r in rows {
            both.push(SummaryRow {
                neighbors: NeighborMode::Grid,
                n: 120,
                ..r
            });
        }
        let lines = neighbor_lines(&both, Preset::Seed).unwrap();
        assert_eq!(lines.len(), 4);
        assert_eq!(lines[0].label, "all-pairs, seq (1 core)");
        assert_eq!(lines[0].points[0].y, 4.0 / 3.0);
        assert_eq!(lines[1].points[0].y, 2.0 / 3.0);
    }

    /// `r` placed by `pin`.
    pub(crate) fn pinned(mut r: SummaryRow, pin: Pin) -> SummaryRow {
        r.pin = pin;
        r
    }

    #[test]
    fn pinned_cells_are_series_of_their_own_and_never_a_strategys_best_cell() {
        use StrategyName::{RayonChunks, RayonIter};
        let rows = vec![
            row(StrategyName::Seq, 1, None, 4.0),
            row(RayonChunks, 2, Some(10), 2.2),
            // Faster, but pinned: not the unpinned series' best cell.
            pinned(row(RayonChunks, 2, Some(10), 1.9), Pin::Spread),
            pinned(row(RayonChunks, 2, Some(5), 2.0), Pin::Compact),
            pinned(row(RayonChunks, 1, Some(5), 4.1), Pin::Spread),
            row(RayonIter, 2, None, 2.0),
        ];
        let g = rows[0].group();
        assert_eq!(
            series(&rows, &g),
            [
                SeriesKey::unpinned(RayonChunks),
                SeriesKey::new(RayonChunks, Pin::Compact),
                SeriesKey::new(RayonChunks, Pin::Spread),
                SeriesKey::unpinned(RayonIter),
            ]
        );
        assert!(is_pinned(&rows, &g));
        assert!(!is_pinned(&rows[..2], &g));
        let none = best_per_cores(&rows, &g, SeriesKey::unpinned(RayonChunks));
        assert_eq!(none.len(), 1);
        assert_eq!((none[0].mean_s, none[0].pin), (2.2, Pin::None));
        let spread = best_per_cores(&rows, &g, SeriesKey::new(RayonChunks, Pin::Spread));
        assert_eq!(
            spread
                .iter()
                .map(|b| (b.cores, b.mean_s))
                .collect::<Vec<_>>(),
            [(1, 4.1), (2, 1.9)]
        );

        let lines = speedup_lines(&rows, &g);
        let labels: Vec<&str> = lines.iter().map(|l| l.label.as_str()).collect();
        assert_eq!(
            labels,
            [
                "rayon-chunks",
                "rayon-chunks (compact)",
                "rayon-chunks (spread)",
                "rayon-iter"
            ]
        );
        let pins: Vec<Pin> = lines.iter().map(Line::pin).collect();
        assert_eq!(pins, [Pin::None, Pin::Compact, Pin::Spread, Pin::None]);
        assert_eq!(lines[0].points[0].y, 4.0 / 2.2);
        assert_eq!(lines[2].points[1].y, 4.0 / 1.9);
        let (eff, _) = efficiency_lines(&rows, &g);
        assert_eq!(eff[2].series, lines[2].series);

        // A chunks chart per placement: the spread one holds only spread cells.
        let wall = chunk_lines(
            &rows,
            &g,
            SeriesKey::new(RayonChunks, Pin::Spread),
            Metric::Wall,
        );
        let ys: Vec<f64> = wall
            .iter()
            .flat_map(|l| l.points.iter().map(|p| p.y))
            .collect();
        assert_eq!(ys, [4.1, 1.9]);
        assert!(wall.iter().all(|l| l.series.is_none()));
    }

    #[test]
    fn the_smt_band_holds_the_core_counts_past_the_physical_cores_up_to_the_logical_cpus() {
        let t = Topology {
            logical_cpus: 8,
            physical_cores: Some(4),
            threads_per_core: Some(2),
            ..Topology::default()
        };
        let band = smt_band(&t, &[1, 2, 4, 6, 8, 10]).unwrap();
        assert_eq!(
            band,
            SmtBand {
                physical_cores: 4,
                to: 8,
                cores: vec![6, 8],
            }
        );
        // S / min(p, 4): the same as S / p up to the physical cores.
        assert_eq!(band.physical_efficiency(3.0, 2), 1.5);
        assert_eq!(band.physical_efficiency(5.0, 8), 1.25);
        // No core count past the physical cores, or only past the logical CPUs: no band.
        assert_eq!(smt_band(&t, &[1, 2, 4]), None);
        assert_eq!(smt_band(&t, &[4, 9]), None);
        // One thread per core (no siblings), or unknown cores: no band.
        let flat = Topology {
            logical_cpus: 2,
            physical_cores: Some(2),
            ..Topology::default()
        };
        assert_eq!(smt_band(&flat, &[1, 2]), None);
        let unknown = Topology {
            logical_cpus: 8,
            ..Topology::default()
        };
        assert_eq!(smt_band(&unknown, &[1, 8]), None);
    }
}
