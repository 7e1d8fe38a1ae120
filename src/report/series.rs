//! Pure functions from summary rows to what the charts and the report show: groups, lines of
//! points, the best cell per core count, speedup spreads, the Karp–Flatt serial fraction.
//!
//! Only cells with `status = ok` and a mean enter a series; failed cells are listed by the
//! report instead. Times are seconds.

use std::collections::BTreeSet;

use crate::results::stats::Interval;

use sph_strategies::StrategyName;

pub use crate::results::key::Group;
use crate::results::rows::{Contended, SummaryRow, fastest};
use crate::sph::neighbors::NeighborMode;
use crate::sph::params::Preset;

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
    /// Whether other work used the machine while the cell was measured.
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
}

impl Line {
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

/// One line per core count: `metric` against chunks, for a chunked `strategy` in `group`
/// (Figures 7 and 8 of the paper).
pub fn chunk_lines(
    rows: &[SummaryRow],
    group: &Group,
    strategy: StrategyName,
    metric: Metric,
) -> Vec<Line> {
    let ok = ok_rows(rows, group);
    let mut out = Vec::new();
    for c in cores(rows, group) {
        let mut points: Vec<Point> = ok
            .iter()
            .filter(|r| r.strategy == strategy && r.cores == c)
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
        out.push(Line {
            label: cores_label(c),
            points,
        });
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
    /// The Karp–Flatt serial fraction at this cell (see [`karp_flatt`]).
    pub fn serial_fraction(&self) -> Option<f64> {
        karp_flatt(self.speedup?, self.cores)
    }
}

/// The fastest usable cell of `strategy` in `group` at each core count, by cores.
pub fn best_per_cores(rows: &[SummaryRow], group: &Group, strategy: StrategyName) -> Vec<Best> {
    let ok = ok_rows(rows, group);
    let mut set: BTreeSet<usize> = BTreeSet::new();
    for r in ok.iter().filter(|r| r.strategy == strategy) {
        set.insert(r.cores);
    }
    set.into_iter()
        .filter_map(|c| {
            // The fastest trustworthy cell; a contended one only when all of them are.
            let r = fastest(
                ok.iter()
                    .copied()
                    .filter(|r| r.strategy == strategy && r.cores == c),
                Contended::LastResort,
            )?;
            let mean_s = r.mean_s?;
            Some(Best {
                cores: c,
                chunks: r.chunks,
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

/// Best lines per strategy for `group` (every strategy but `seq`): speedup against cores,
/// with the best cell's 95 % interval of the speedup.
pub fn speedup_lines(rows: &[SummaryRow], group: &Group) -> Vec<Line> {
    let Some(seq) = seq_mean(rows, group) else {
        return Vec::new();
    };
    strategies(rows, group)
        .into_iter()
        .filter(|&s| s != StrategyName::Seq)
        .filter_map(|s| {
            let points: Vec<Point> = best_per_cores(rows, group, s)
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
                label: s.to_string(),
                points,
            })
        })
        .collect()
}

/// Best runtime against cores for one strategy (bars: 95 % interval of the mean).
pub fn runtime_line(best: &[Best], label: &str) -> Line {
    Line {
        label: label.to_owned(),
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
                lines.push(Line { label, points });
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

/// The chunks lines of a strategy in a form for [`chunking_stops_paying`]: per core count,
/// `(cores, [(chunks, mean, stddev)])`.
pub fn chunk_table(
    rows: &[SummaryRow],
    group: &Group,
    strategy: StrategyName,
) -> Vec<(usize, Vec<ChunkCell>)> {
    let ok = ok_rows(rows, group);
    cores(rows, group)
        .into_iter()
        .map(|c| {
            let mut v: Vec<ChunkCell> = ok
                .iter()
                .filter(|r| r.strategy == strategy && r.cores == c)
                .filter(|r| r.contended != Some(true))
                .filter_map(|r| Some((r.chunks?, r.mean_s?, r.stddev_s.unwrap_or(0.0))))
                .collect();
            v.sort_by_key(|t| t.0);
            (c, v)
        })
        .filter(|(_, v)| !v.is_empty())
        .collect()
}

#[cfg(test)]
mod tests {
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
        let best = best_per_cores(&rows, &g, StrategyName::RayonChunks);
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
        let lines = chunk_lines(&rows, &g, StrategyName::RayonChunks, Metric::Wall);
        assert_eq!(lines.len(), 2);
        assert_eq!(lines[0].label, "1 core");
        assert_eq!(lines[0].points[0].x, 5.0);
        assert_eq!(lines[0].min_index(), Some(0));
        assert_eq!(lines[1].min_index(), Some(1));
        let cpu = chunk_lines(&rows, &g, StrategyName::RayonChunks, Metric::Cpu);
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
}
