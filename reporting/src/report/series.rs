//! Pure functions from summary rows and a group's view ([`GroupView`]) to what the charts and
//! the report show: lines of points with their intervals, chunk tables, the SMT band.
//!
//! Only cells with `status = ok` and a mean enter a series; failed cells are listed by the
//! report instead. Times are seconds. Which rows form a series: [`super::select`]; a best
//! cell's numbers: [`super::cell`].

use std::collections::BTreeSet;

use super::cell::{Best, Runs};
use super::select::{SeriesKey, cores, groups, ok_rows};
use super::view::GroupView;
pub use sph_harness::results::key::Group;
use sph_harness::results::rows::{Contended, SummaryRow, fastest};
use sph_harness::topology::{Pin, Topology};
use sph_solver::models::Preset;
use sph_solver::sph::neighbors::NeighborMode;

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
    /// The strategy and placement it shows, where it shows one (its colour and line style);
    /// `None` for lines of core counts or neighbour searches.
    pub series: Option<SeriesKey>,
    /// Each trial behind the points, as (its point's x, its value): chart 1 draws them beside
    /// their mean.
    pub dots: Vec<(f64, f64)>,
}

impl Line {
    /// A line that shows no series (see [`Line::series`]) and no trials.
    pub fn new(label: impl Into<String>, points: Vec<Point>) -> Line {
        Line {
            label: label.into(),
            points,
            series: None,
            dots: Vec::new(),
        }
    }

    /// A line of the series `key`, without trials.
    pub fn of(key: SeriesKey, points: Vec<Point>) -> Line {
        Line {
            series: Some(key),
            ..Line::new(key.to_string(), points)
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
    /// Mean wall seconds (bars: the 95 % interval; dots: each trial).
    Wall,
    /// Mean CPU seconds, user + system.
    Cpu,
}

/// One line per core count: `metric` against chunks, for the series `key` of a chunked
/// strategy in the grid rows of `view` (Figures 7 and 8 of the paper); runtime lines carry
/// each trial as a dot.
pub fn chunk_lines(view: &GroupView, key: SeriesKey, metric: Metric) -> Vec<Line> {
    let (rows, group) = (&view.rows, &view.group);
    let ok = ok_rows(rows, group);
    let mut out = Vec::new();
    for c in cores(rows, group) {
        let cells: Vec<&SummaryRow> = ok
            .iter()
            .copied()
            .filter(|r| key.holds(r) && r.cores == c)
            .collect();
        let mut dots: Vec<(f64, f64)> = Vec::new();
        for r in cells.iter().filter(|_| metric == Metric::Wall) {
            if let Some(k) = r.chunks {
                dots.extend(view.runs(r).walls().map(|w| (k as f64, w)));
            }
        }
        let mut points: Vec<Point> = cells
            .iter()
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
            dots,
            ..Line::new(cores_label(c), points)
        });
    }
    out
}

/// `1 core`, `3 cores`.
pub fn cores_label(c: usize) -> String {
    format!("{c} {}", if c == 1 { "core" } else { "cores" })
}

/// A best cell as a point at its cores: `y` and its interval `(lo, hi)`.
fn at_cores(b: &Best, y: f64, (lo, hi): (f64, f64)) -> Point {
    Point {
        x: b.cores as f64,
        y,
        lo,
        hi,
        oversubscribed: b.oversubscribed,
        contended: b.contended,
    }
}

/// Per series of `bests` ([`GroupView::series_bests`]): speedup against cores, bars the 95 %
/// interval of the best cell's paired speedup.
pub fn speedup_lines(bests: &[(SeriesKey, Vec<Best>)]) -> Vec<Line> {
    bests
        .iter()
        .filter_map(|(key, best)| {
            let points: Vec<Point> = best
                .iter()
                .filter_map(|b| {
                    let y = b.speedup?;
                    let i = b.speedup_ci.map_or((y, y), |i| (i.low, i.high));
                    Some(at_cores(b, y, i))
                })
                .collect();
            (!points.is_empty()).then(|| Line::of(*key, points))
        })
        .collect()
}

/// Best runtime against cores for one series (bars: 95 % interval of the typical time).
pub fn runtime_line(best: &[Best], key: SeriesKey) -> Line {
    let points = best
        .iter()
        .map(|b| {
            let i = b.mean_ci.map_or((b.mean_s, b.mean_s), |i| (i.low, i.high));
            at_cores(b, b.mean_s, i)
        })
        .collect();
    Line::of(key, points)
}

/// Per series of `bests`, efficiency against cores (every core count with a speedup) and the
/// Karp–Flatt serial fraction with its interval, only where [`Best::serial_fraction`] gives
/// one.
pub fn efficiency_lines(bests: &[(SeriesKey, Vec<Best>)]) -> (Vec<Line>, Vec<Line>) {
    let mut eff = Vec::new();
    let mut kf = Vec::new();
    for (key, best) in bests {
        let e: Vec<Point> = best
            .iter()
            .filter_map(|b| {
                let y = b.speedup? / b.cores as f64;
                Some(at_cores(b, y, (y, y)))
            })
            .collect();
        if e.is_empty() {
            continue;
        }
        eff.push(Line::of(*key, e));
        let k: Vec<Point> = best
            .iter()
            .filter_map(|b| {
                let (e, i) = b.serial_fraction()?;
                Some(at_cores(b, e, (i.low, i.high)))
            })
            .collect();
        if !k.is_empty() {
            kf.push(Line::of(*key, k));
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

/// For a chunks line (chunks ascending, each cell's grid runs): the smallest chunk count from
/// which no larger count is faster by the paired rounds (the 95 % interval of the time ratio
/// below 1). `None` for an empty line, or where some pair has no interval (under 3 rounds,
/// runs that do not pair): then nothing is known.
pub fn chunking_stops_paying(line: &[(usize, Runs)]) -> Option<usize> {
    let mut from = None;
    for (i, (k, runs)) in line.iter().enumerate().rev() {
        let mut beaten = false;
        for (_, later) in &line[i + 1..] {
            let r = later.ratio(runs)?;
            r.interval?;
            beaten |= r.resolved() && r.value < 1.0;
        }
        if !beaten {
            from = Some(*k);
        }
    }
    from
}

/// The chunks lines of a series in the grid rows of `view`, for [`chunking_stops_paying`]:
/// per core count, `(cores, [(chunks, runs)])` of its cells measured without contention.
pub fn chunk_table(view: &GroupView, key: SeriesKey) -> Vec<(usize, Vec<(usize, Runs)>)> {
    let ok = ok_rows(&view.rows, &view.group);
    cores(&view.rows, &view.group)
        .into_iter()
        .map(|c| {
            let mut v: Vec<(usize, Runs)> = ok
                .iter()
                .filter(|r| key.holds(r) && r.cores == c && r.contended != Some(true))
                .filter_map(|r| Some((r.chunks?, view.runs(r))))
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
    use crate::report::cell::karp_flatt;
    use crate::report::select::{is_pinned, series};
    use crate::report::view::tests::{of_rows, view, views};
    use sph_harness::results::fixtures::row;
    use sph_harness::results::rows::Status;
    use sph_harness::results::stats::Interval;
    use sph_strategies::StrategyName;

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
    fn the_serial_fraction_carries_the_speedups_interval_and_needs_it_above_zero() {
        let v = of_rows(sample());
        let mut b = v.best_per_cores(SeriesKey::unpinned(StrategyName::RayonIter))[0].clone();
        // Speedup 1.6 [1.5–1.7] at 2 cores: e = 0.25, from e(1.7) to e(1.5).
        (b.speedup, b.speedup_ci) = (
            Some(1.6),
            Some(Interval {
                low: 1.5,
                high: 1.7,
            }),
        );
        let (e, i) = b.serial_fraction().unwrap();
        assert!((e - 0.25).abs() < 1e-12);
        assert!((i.low - (2.0 / 1.7 - 1.0)).abs() < 1e-12);
        assert!((i.high - (2.0 / 1.5 - 1.0)).abs() < 1e-12);
        // An interval reaching the ideal speedup (e ≤ 0), a speedup of 1 or less, or no
        // interval: none.
        b.speedup_ci = Some(Interval {
            low: 1.5,
            high: 2.0,
        });
        assert_eq!(b.serial_fraction(), None);
        (b.speedup, b.speedup_ci) = (
            Some(0.9),
            Some(Interval {
                low: 0.8,
                high: 0.95,
            }),
        );
        assert_eq!(b.serial_fraction(), None);
        (b.speedup, b.speedup_ci) = (Some(1.6), None);
        assert_eq!(b.serial_fraction(), None);
    }

    #[test]
    fn the_best_cell_per_cores_is_the_fastest_usable_one() {
        let v = of_rows(sample());
        let best = v.best_per_cores(SeriesKey::unpinned(StrategyName::RayonChunks));
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
    fn chunk_lines_have_one_line_per_cores_sorted_by_chunks_each_trial_a_dot() {
        use StrategyName::{RayonChunks, Seq};
        let none = Pin::None;
        let v = view(&[
            (Seq, 1, None, none, &[4.0, 4.0, 4.0]),
            (RayonChunks, 1, Some(10), none, &[4.2, 4.3, 4.1]),
            (RayonChunks, 1, Some(5), none, &[4.1, 4.0, 4.2]),
            (RayonChunks, 2, Some(5), none, &[2.5, 2.6, 2.4]),
            (RayonChunks, 2, Some(10), none, &[2.2, 2.1, 2.3]),
        ]);
        let key = SeriesKey::unpinned(RayonChunks);
        let lines = chunk_lines(&v, key, Metric::Wall);
        assert_eq!(lines.len(), 2);
        assert_eq!(lines[0].label, "1 core");
        assert_eq!(lines[0].points[0].x, 5.0);
        assert_eq!(lines[0].min_index(), Some(0));
        assert_eq!(lines[1].min_index(), Some(1));
        // Every trial of the line is a dot at its cell's chunks.
        assert_eq!(
            lines[1].dots,
            [
                (5.0, 2.5),
                (5.0, 2.6),
                (5.0, 2.4),
                (10.0, 2.2),
                (10.0, 2.1),
                (10.0, 2.3)
            ]
        );
        let cpu = chunk_lines(&v, key, Metric::Cpu);
        assert!((cpu[1].points[1].y - 4.4).abs() < 1e-12);
        assert!(cpu.iter().all(|l| l.dots.is_empty()));
    }

    #[test]
    fn speedup_lines_skip_seq_and_carry_the_paired_interval_and_oversubscription() {
        let v = of_rows(sample());
        let lines = speedup_lines(&v.series_bests());
        let labels: Vec<&str> = lines.iter().map(|l| l.label.as_str()).collect();
        assert_eq!(labels, ["rayon-chunks", "rayon-iter"]);
        let p = lines[1].points[1];
        assert_eq!((p.x, p.y), (3.0, 4.0 / 2.4));
        assert!(p.oversubscribed);
        assert!(p.lo < p.y && p.y < p.hi);
        let (eff, kf) = efficiency_lines(&v.series_bests());
        assert_eq!(eff[1].points[0].y, 1.0);
        // rayon-chunks at 2 cores: speedup 1.82 [1.73–1.91], so e from 0.0476 to 0.156.
        assert_eq!(kf[0].points.len(), 1, "no Karp–Flatt value at 1 core");
        let k = kf[0].points[0];
        assert!(k.lo > 0.0 && k.lo < k.y && k.y < k.hi, "{k:?}");
    }

    #[test]
    fn chunking_stops_paying_where_no_larger_count_is_faster_by_the_paired_rounds() {
        use StrategyName::{RayonChunks, Seq};
        let none = Pin::None;
        let v = view(&[
            (Seq, 1, None, none, &[4.0, 4.4, 3.6]),
            (RayonChunks, 2, Some(2), none, &[3.0, 3.3, 2.7]),
            (RayonChunks, 2, Some(5), none, &[2.0, 2.2, 1.8]),
            // Faster on average, but not in every round.
            (RayonChunks, 2, Some(10), none, &[1.9, 2.3, 1.7]),
        ]);
        let table = chunk_table(&v, SeriesKey::unpinned(RayonChunks));
        assert_eq!(chunking_stops_paying(&table[0].1), Some(5));
        assert_eq!(chunking_stops_paying(&table[0].1[..1]), Some(2));
        assert_eq!(chunking_stops_paying(&[]), None);
        // Without trials nothing pairs, and nothing is known.
        let bare = of_rows(sample());
        let table = chunk_table(&bare, SeriesKey::unpinned(RayonChunks));
        assert_eq!(chunking_stops_paying(&table[0].1), None);
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
        let v = views(rows, Vec::new()).remove(0);
        let none = v.best_per_cores(SeriesKey::unpinned(RayonChunks));
        assert_eq!(none.len(), 1);
        assert_eq!((none[0].mean_s, none[0].pin), (2.2, Pin::None));
        let spread = v.best_per_cores(SeriesKey::new(RayonChunks, Pin::Spread));
        assert_eq!(
            spread
                .iter()
                .map(|b| (b.cores, b.mean_s))
                .collect::<Vec<_>>(),
            [(1, 4.1), (2, 1.9)]
        );

        let bests = v.series_bests();
        let lines = speedup_lines(&bests);
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
        let (eff, _) = efficiency_lines(&bests);
        assert_eq!(eff[2].series, lines[2].series);

        // A chunks chart per placement: the spread one holds only spread cells.
        let wall = chunk_lines(&v, SeriesKey::new(RayonChunks, Pin::Spread), Metric::Wall);
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
