//! Toy against real workload: does the strategy ranking hold?
//!
//! The study's toy workload is Müller's pixel-unit model (the `seed` or `cpp` preset, a kernel
//! radius of one initial spacing: a handful of neighbours per particle, about 5–12 over the
//! seed dam break at N = 1000); its real one is `wcsph` (weakly compressible SPH in SI units,
//! support 2.6 spacings: 20 neighbours per fluid particle on the initial lattice, and wall
//! particles besides). When the rows hold both, each wcsph group is set beside the toy group
//! with the same neighbour search whose N is nearest (by absolute difference; then the nearest
//! step count; then the first listed), and at every core count measured in both the strategies
//! are ranked by their best cell there ([`GroupView::best_per_cores`]: the rule of the
//! report's tables), of its unpinned cells (`pin = none`: placements are compared in the
//! groups' own sections). [`super::rank_shift::rank_shift`] decides what each workload's
//! paired rounds support; [`markdown`] writes the section.
//!
//! [`section`] is pure: views in, [`Section`] out; `None` when they lack either workload, so a
//! report without wcsph is unchanged.

use std::fmt::Write as _;

use sph_strategies::StrategyName;

use super::cell;
use super::cell::Best;
use super::findings::Finding;
use super::numbers::{interval, plus_minus, sig, times};
use super::rank_shift::rank_shift;
use super::select;
use super::series::{self, Group};
use super::table::{Column, Table};
use super::verdict::Entry;
use super::view::GroupView;
use sph_harness::results::key::LabelStyle;
use sph_harness::results::stats::Interval;
use sph_solver::models::Preset;

/// The section: one comparison per wcsph group.
#[derive(Debug, Clone, PartialEq)]
pub struct Section {
    /// In the order the wcsph groups first appear.
    pub pairs: Vec<Pairing>,
}

/// One wcsph group beside its toy group.
#[derive(Debug, Clone, PartialEq)]
pub struct Pairing {
    /// The wcsph group and its cost.
    pub real: Workload,
    /// The toy group (`None`: no Müller group with the same neighbour search).
    pub toy: Option<Workload>,
    /// Per core count measured in both, by cores.
    pub at: Vec<RankingAt>,
}

/// A group and what one particle-step of its `seq` reference costs.
#[derive(Debug, Clone, PartialEq)]
pub struct Workload {
    /// The group.
    pub group: Group,
    /// `seq`'s mean wall time per particle-step, nanoseconds, with its 95 % interval
    /// (`None` without a usable `seq` cell).
    pub ns_per_particle_step: Option<(f64, Option<Interval>)>,
}

/// The ranking at one core count.
#[derive(Debug, Clone, PartialEq)]
pub struct RankingAt {
    /// Worker threads.
    pub cores: usize,
    /// One row per strategy: by toy rank, then those measured on wcsph only.
    pub rows: Vec<RankRow>,
    /// What the intervals support ([`Finding::RankShift`]).
    pub finding: Finding,
}

/// One strategy's place on each workload.
#[derive(Debug, Clone, PartialEq)]
pub struct RankRow {
    /// The strategy.
    pub strategy: StrategyName,
    /// Its rank (1 = lowest mean; equal means share one) and best cell on the toy workload.
    pub toy: Option<(usize, Best)>,
    /// The same on wcsph.
    pub real: Option<(usize, Best)>,
}

/// The comparison of `views`, or `None` unless they hold a `wcsph` group and a Müller group.
pub fn section(views: &[GroupView]) -> Option<Section> {
    let reals: Vec<&GroupView> = views
        .iter()
        .filter(|v| v.group.preset == Preset::Wcsph)
        .collect();
    if reals.is_empty() || !views.iter().any(|v| v.group.preset.is_mueller()) {
        return None;
    }
    let pairs = reals
        .into_iter()
        .map(|real| {
            let toy = nearest_toy(views, &real.group);
            Pairing {
                real: workload(real),
                toy: toy.map(workload),
                at: toy.map_or_else(Vec::new, |t| rankings(t, real)),
            }
        })
        .collect();
    Some(Section { pairs })
}

/// The Müller group with `real`'s neighbour search nearest in N, then in steps (the first
/// listed of equals).
fn nearest_toy<'a>(views: &'a [GroupView], real: &Group) -> Option<&'a GroupView> {
    views
        .iter()
        .filter(|v| v.group.preset.is_mueller() && v.group.neighbors == real.neighbors)
        .min_by_key(|v| {
            (
                v.group.n.abs_diff(real.n),
                v.group.steps.abs_diff(real.steps),
            )
        })
}

fn workload(v: &GroupView) -> Workload {
    let g = &v.group;
    let per = |s: f64| s / (g.n as f64 * g.steps as f64) * 1e9;
    let seq = v.reference();
    Workload {
        group: *g,
        ns_per_particle_step: seq.and_then(|r| {
            let ci = cell::interval(r.mean_ci_low_s, r.mean_ci_high_s).map(|i| Interval {
                low: per(i.low),
                high: per(i.high),
            });
            Some((per(r.mean_s?), ci))
        }),
    }
}

/// Each strategy's best cell at `cores` in `v` (every strategy but `seq`), fastest first.
fn entries(v: &GroupView, cores: usize) -> Vec<Entry> {
    let mut out: Vec<Entry> = v
        .parallel_strategies()
        .into_iter()
        .filter_map(|s| {
            let best = v.best_per_cores(select::SeriesKey::unpinned(s));
            Some((s, Box::new(best.into_iter().find(|b| b.cores == cores)?)))
        })
        .collect();
    out.sort_by(|a, b| a.1.mean_s.total_cmp(&b.1.mean_s));
    out
}

fn rankings(toy: &GroupView, real: &GroupView) -> Vec<RankingAt> {
    let real_cores = real.cores();
    toy.cores()
        .into_iter()
        .filter(|c| real_cores.contains(c))
        .map(|c| {
            let (t, r) = (entries(toy, c), entries(real, c));
            // Equal means share a rank (1, 1, 3): a tie is not an order.
            let ranked = |v: &[Entry], s: StrategyName| {
                let (_, b) = v.iter().find(|(x, _)| *x == s)?;
                let ahead = v.iter().filter(|(_, o)| o.mean_s < b.mean_s).count();
                Some((ahead + 1, (**b).clone()))
            };
            let mut order: Vec<StrategyName> = t.iter().map(|(s, _)| *s).collect();
            order.extend(
                r.iter()
                    .map(|(s, _)| *s)
                    .filter(|s| !t.iter().any(|e| e.0 == *s)),
            );
            RankingAt {
                cores: c,
                rows: order
                    .into_iter()
                    .map(|s| RankRow {
                        strategy: s,
                        toy: ranked(&t, s),
                        real: ranked(&r, s),
                    })
                    .collect(),
                finding: Finding::RankShift(Box::new(rank_shift(c, &t, &r))),
            }
        })
        .collect()
}

/// The section as Markdown (empty for `None`).
pub fn markdown(section: Option<&Section>) -> String {
    let Some(section) = section else {
        return String::new();
    };
    let mut md = String::new();
    let _ = writeln!(md, "## Toy vs real workload: does the ranking hold?\n");
    let _ = writeln!(
        md,
        "The toy workload is Müller's pixel-unit model (the seed or cpp preset: a kernel \
         radius of one initial spacing, a handful of neighbours per particle: about 5–12 in \
         the seed dam break); the real one is wcsph (weakly compressible SPH in SI units: \
         support 2.6 spacings, about 20 neighbours per fluid particle, and wall particles \
         besides; its N counts the fluid \
         particles, 2R² at resolution R). Each wcsph group is set beside the toy group with \
         the same neighbour search whose N is nearest. At each core count measured in both, \
         the strategies are ranked by their best cell (as in the tables below; equal means \
         share a rank); speedups are over each group's own `seq`. A change of place is \
         stated only where both orders are resolved, each by its own workload's paired \
         rounds: the two groups ran at different times, so no number of one is set against \
         the other's.\n"
    );
    for p in &section.pairs {
        pairing(&mut md, p);
    }
    md
}

fn pairing(md: &mut String, p: &Pairing) {
    let real = p.real.group.label(LabelStyle::Report);
    let Some(toy) = &p.toy else {
        let _ = writeln!(
            md,
            "### {real}\n\nNo toy group with the same neighbour search ({}) was measured: \
             nothing to compare with.\n",
            p.real.group.neighbors
        );
        return;
    };
    let _ = writeln!(
        md,
        "### {real} against {}\n",
        toy.group.label(LabelStyle::Report)
    );
    let _ = writeln!(md, "{}\n", cost(toy, &p.real));
    if p.at.is_empty() {
        let _ = writeln!(
            md,
            "No core count has a usable parallel cell in both groups: no ranking to compare.\n"
        );
    }
    for at in &p.at {
        let _ = writeln!(md, "**{}**\n", series::cores_label(at.cores));
        let mut t = Table::new([
            Column::left("strategy"),
            Column::left(format!(
                "toy ({} preset, N = {}): rank, speedup (± 95 % CI)",
                toy.group.preset, toy.group.n
            )),
            Column::left(format!(
                "wcsph (N = {}): rank, speedup (± 95 % CI)",
                p.real.group.n
            )),
        ]);
        for r in &at.rows {
            t.row([
                r.strategy.to_string(),
                place(r.toy.as_ref()),
                place(r.real.as_ref()),
            ]);
        }
        let _ = writeln!(md, "{t}\n- {}\n", at.finding.sentence());
    }
}

/// What a particle-step costs on each workload, in one sentence.
fn cost(toy: &Workload, real: &Workload) -> String {
    let ns = |w: &Workload| {
        w.ns_per_particle_step.map_or_else(
            || "— (no usable `seq` cell)".to_owned(),
            |(v, ci)| format!("{} ns{}", sig(v), interval(ci)),
        )
    };
    let ratio = match (toy.ns_per_particle_step, real.ns_per_particle_step) {
        (Some((t, _)), Some((r, _))) => {
            format!(": one wcsph particle-step costs {} a toy one", times(r / t))
        }
        _ => String::new(),
    };
    format!(
        "Cost of one particle-step, `seq` at 1 core (its mean over N × steps): toy {} (N = {}, \
         {}), wcsph {} per fluid particle (N = {}, {}){ratio}.",
        ns(toy),
        toy.group.n,
        sph_harness::output::console::plural(toy.group.steps, "step", "steps"),
        ns(real),
        real.group.n,
        sph_harness::output::console::plural(real.group.steps, "step", "steps"),
    )
}

/// A strategy's place on one workload: `1 · 1.98 ± 0.03×, 50 chunks`, with its flags.
fn place(ranked: Option<&(usize, Best)>) -> String {
    let Some((rank, b)) = ranked else {
        return "— (not measured)".to_owned();
    };
    let speed = b.speedup.map_or_else(
        || format!("{} s", sig(b.mean_s)),
        |s| plus_minus(s, b.speedup_ci),
    );
    let chunks = b
        .chunks
        .map_or_else(String::new, |k| format!(", {k} chunks"));
    let flags: String = b.flags().map(|f| format!(" {f}")).collect();
    format!("{rank} · {speed}{chunks}{flags}")
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::report::view::tests::{measured_in, views};
    use sph_harness::results::rows::Phase;
    use sph_harness::topology::Pin;
    use sph_solver::sph::neighbors::NeighborMode;

    /// The views of three groups (seed N = 1000 and 10 000, wcsph N = 3200, all grid), each
    /// of seq (4 s) and rayon-chunks and rayon-iter at 2 cores, every cell drifting alike
    /// from round to round; wcsph's search `wcsph_search`.
    fn toy_and_real(wcsph_search: NeighborMode) -> Vec<GroupView> {
        let drift = |mean: f64| [mean, mean * 1.1, mean * 0.9];
        let (mut rows, mut trials) = (Vec::new(), Vec::new());
        for (preset, n, chunks, iter) in [
            (Preset::Seed, 1000, 2.0, 2.6),
            (Preset::Seed, 10000, 2.0, 2.6),
            (Preset::Wcsph, 3200, 2.6, 2.0),
        ] {
            let group = Group {
                preset,
                neighbors: match preset {
                    Preset::Wcsph => wcsph_search,
                    _ => NeighborMode::Grid,
                },
                n,
                steps: 3,
            };
            let (r, t) = measured_in(
                group,
                &[
                    (StrategyName::Seq, 1, None, Pin::None, &drift(4.0)),
                    (
                        StrategyName::RayonChunks,
                        2,
                        Some(10),
                        Pin::None,
                        &drift(chunks),
                    ),
                    (StrategyName::RayonIter, 2, None, Pin::None, &drift(iter)),
                ],
                Phase::Grid,
            );
            rows.extend(r);
            trials.extend(t);
        }
        views(rows, trials)
    }

    #[test]
    fn without_a_wcsph_group_or_a_toy_group_there_is_no_section() {
        let all = toy_and_real(NeighborMode::Grid);
        let (seed, wcsph): (Vec<GroupView>, Vec<GroupView>) = all
            .into_iter()
            .partition(|v| v.group.preset == Preset::Seed);
        assert_eq!(section(&seed), None);
        assert_eq!(section(&wcsph), None);
        assert_eq!(markdown(None), "");
    }

    #[test]
    fn a_wcsph_group_is_set_beside_the_toy_group_of_its_search_nearest_in_n() {
        let s = section(&toy_and_real(NeighborMode::Grid)).unwrap();
        assert_eq!(s.pairs.len(), 1);
        let p = &s.pairs[0];
        assert_eq!(p.toy.as_ref().map(|t| t.group.n), Some(1000));
        // 4 s over 1000 particles × 3 steps; 4 s over 3200 × 3.
        let (toy_ns, _) = p.toy.as_ref().unwrap().ns_per_particle_step.unwrap();
        assert!((toy_ns - 4e9 / 3000.0).abs() < 1e-3, "{toy_ns}");
        let (real_ns, ci) = p.real.ns_per_particle_step.unwrap();
        assert!((real_ns - 4e9 / 9600.0).abs() < 1e-3, "{real_ns}");
        assert!(ci.is_some_and(|i| i.low < real_ns && real_ns < i.high));
        // Only 2 cores has parallel cells in both.
        assert_eq!(p.at.len(), 1);
        let ranks: Vec<_> = p.at[0]
            .rows
            .iter()
            .map(|r| {
                (
                    r.strategy,
                    r.toy.as_ref().map(|t| t.0),
                    r.real.as_ref().map(|t| t.0),
                )
            })
            .collect();
        assert_eq!(
            ranks,
            [
                (StrategyName::RayonChunks, Some(1), Some(2)),
                (StrategyName::RayonIter, Some(2), Some(1)),
            ]
        );
    }

    #[test]
    fn a_wcsph_group_without_a_toy_group_of_its_search_says_so() {
        let s = section(&toy_and_real(NeighborMode::AllPairs)).unwrap();
        assert_eq!(s.pairs[0].toy, None);
        let md = markdown(Some(&s));
        assert!(
            md.contains("No toy group with the same neighbour search (all-pairs)"),
            "{md}"
        );
    }

    #[test]
    fn the_section_names_both_groups_ranks_speedups_and_the_finding() {
        let md = markdown(section(&toy_and_real(NeighborMode::Grid)).as_ref());
        for needle in [
            "## Toy vs real workload: does the ranking hold?",
            "### wcsph preset, grid, N = 3200, 3 steps against seed preset, grid, N = 1000, 3 steps",
            // 4 s over 3000 and 9600 particle-steps.
            "toy 1330000 ns [",
            "(N = 1000, 3 steps), wcsph 417000 ns [",
            "per fluid particle (N = 3200, 3 steps): one wcsph particle-step costs 0.313× a toy \
             one.",
            "| rayon-chunks | 1 · 2.00 ± 0.00×, 10 chunks | 2 · 1.54 ± 0.00×, 10 chunks |",
            "| rayon-iter | 2 · 1.54 ± 0.00× | 1 · 2.00 ± 0.00× |",
            "- At 2 cores, the winner changes: **rayon-chunks** is fastest on the toy workload \
             and **rayon-iter** on wcsph",
            // Why no number of one workload is set against the other's.
            "the two groups ran at different times",
        ] {
            assert!(md.contains(needle), "lacks {needle:?}:\n{md}");
        }
    }
}
