//! The findings of a group: sentences that never claim more than the data shows.
//!
//! - Every comparison of two cells pairs their runs by round ([`order`]): the geometric mean
//!   of the per-round ratios of their times, with its 95 % Student-t interval. One cell is
//!   called faster only where that interval excludes 1; otherwise the two are **not
//!   distinguishable**. Two separate intervals are never compared.
//! - The cells compared are each strategy's best ones ([`GroupView::best_per_cores`]): from the
//!   confirmation rounds where the group has them, so the runs that chose a cell do not also
//!   measure it.
//! - Under [`MIN_ROUNDS`] rounds there is no interval and so no finding; a sweep whose rounds
//!   do not pair (written before rounds, or `--schedule cells`) gets none either ([`Withheld`]).
//! - Contended cells (other work used the machine) enter no finding; the sentence says how
//!   many were left out.
//! - At one core every strategy does `seq`'s work: a paired speedup whose interval excludes 1
//!   there is the strategy's own cost or gain on one thread, and is stated as such.
//! - The Karp–Flatt serial fraction is given only with its interval, and only where that
//!   interval lies above 0 ([`Best::serial_fraction`]), as a measurement at that core count,
//!   never extrapolated.
//! - Each strategy at each placement (`sweep --pin`) is a series of its own
//!   ([`select::SeriesKey`]); two placements are compared cell against cell
//!   ([`super::placements`]).
//! - Across workloads ([`super::rank_shift`]): a winner is named only where it is resolved on
//!   both; a strategy has moved only where both orders are resolved.
//!
//! [`findings`] decides what the data supports, as [`Finding`] values; [`Finding::sentence`]
//! words each one.

use super::cell::Best;
use super::numbers::{faster, interval, plus_minus, sig};
use super::paper;
use super::placements::Placements;
use super::rank_shift::RankShift;
use super::select;
use super::select::SeriesKey;
use super::series;
use super::verdict::{
    Entry, Order, Verdict, and_list, calm, describe, named, order, trusted, verdict,
};
use super::view::{Design, GroupView};
use sph_harness::results::intervals::{MIN_ROUNDS, Ratio};
use sph_harness::results::stats::Interval;

/// What the data of a group supports, decided before it is worded.
#[derive(Debug, Clone, PartialEq)]
pub enum Finding {
    /// No finding is drawn from the group, and why.
    Withheld(Withheld),
    /// The group's `seq` reference was contended: no speedup-based finding follows.
    ContendedReference,
    /// Who is fastest at one core count, if anyone can be said to be.
    AtCores(AtCores),
    /// Each strategy's best cell at one core against `seq` of the same rounds.
    OneCore(Vec<Best>),
    /// Two placements of a strategy, compared where both were measured.
    Placements(Placements),
    /// The grid's best chunks against its runner-up, both measured again in the
    /// confirmation rounds, per core count.
    BestChunks(Vec<(Best, Best)>),
    /// Where more chunks stop paying for a chunked strategy.
    ChunkingStops {
        /// The strategy, at one placement.
        series: SeriesKey,
        /// (chunks from which more stop paying, at this many cores), by cores.
        from: Vec<(usize, usize)>,
    },
    /// The Karp–Flatt serial fraction of the fastest trusted cell at the most cores, with its
    /// interval.
    SerialFraction {
        /// The cell.
        best: Best,
        /// The serial fraction e.
        e: f64,
        /// Its 95 % interval.
        ci: Interval,
    },
    /// The paper's published speedups beside the best here, per comparable core count.
    AgainstPaper(Vec<PaperPoint>),
    /// How the strategy ranking changes from the toy workload to wcsph at one core count
    /// (boxed: it is the largest finding by far).
    RankShift(Box<RankShift>),
}

/// Why a group gets no finding.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Withheld {
    /// Its sweep's rounds do not pair.
    Design(Design),
    /// Its cells ran this many rounds, fewer than [`MIN_ROUNDS`].
    Rounds(usize),
    /// Its directory has no `trials.csv`: its statistics could not be checked against the
    /// runs, and no runs pair.
    Unchecked,
}

/// The verdict at one core count, with what its sentence needs.
#[derive(Debug, Clone, PartialEq)]
pub struct AtCores {
    /// Worker threads.
    pub cores: usize,
    /// Some cell there had more threads than the machine.
    pub oversubscribed: bool,
    /// Contended cells left out.
    pub contended: usize,
    /// Whether the winner's speedup may be stated (more than 1 core, trusted reference).
    pub show_speedup: bool,
    /// The verdict on the cells measured without contention.
    pub verdict: Verdict,
}

/// One core count of [`Finding::AgainstPaper`].
#[derive(Debug, Clone, PartialEq)]
pub struct PaperPoint {
    /// The best cell here (the highest speedup).
    pub best: Best,
    /// The paper's speedup at these cores.
    pub paper: f64,
}

/// The paired speedup of `b` over `seq` as a ratio.
pub fn speedup(b: &Best) -> Option<Ratio> {
    Some(Ratio {
        value: b.speedup?,
        interval: b.speedup_ci,
        rounds: b.runs.rounds.len(),
    })
}

/// The findings for the group of `view`.
pub fn findings(view: &GroupView) -> Vec<Finding> {
    if view.unchecked {
        return vec![Finding::Withheld(Withheld::Unchecked)];
    }
    if !view.design.pairs() {
        return vec![Finding::Withheld(Withheld::Design(view.design))];
    }
    let usable = view.findings_rows().iter().filter(|r| r.is_usable());
    match usable.map(|r| r.trials).max() {
        None => return Vec::new(),
        Some(k) if k < MIN_ROUNDS => return vec![Finding::Withheld(Withheld::Rounds(k))],
        Some(_) => {}
    }
    let bests = view.series_bests();
    // A contended reference makes every speedup doubtful: none enters a finding then.
    let seq_trusted = view.reference().is_none_or(|r| r.contended != Some(true));
    let mut out = Vec::new();
    if !seq_trusted {
        out.push(Finding::ContendedReference);
    }
    for c in view.cores() {
        let at: Vec<Entry> = bests
            .iter()
            .filter_map(|(k, b)| {
                let b = b.iter().find(|b| b.cores == c)?;
                Some((k.strategy, Box::new(b.clone())))
            })
            .collect();
        out.extend(at_cores(c, &at, seq_trusted).map(Finding::AtCores));
        let one: Vec<Best> = at.into_iter().map(|(_, b)| *b).filter(calm).collect();
        if c == 1 && seq_trusted && one.iter().any(|b| b.speedup_ci.is_some()) {
            out.push(Finding::OneCore(one));
        }
    }
    let strategies = view.parallel_strategies();
    out.extend(super::placements::compare(view, &strategies, seq_trusted).map(Finding::Placements));
    out.extend(best_chunks(view, &bests));
    out.extend(chunking(view, &bests));
    if seq_trusted {
        out.extend(karp_flatt(&bests));
        out.extend(against_paper(view, &bests));
    }
    out
}

/// The verdict at `cores` on the cells `at`, the contended ones left out.
fn at_cores(cores: usize, at: &[Entry], seq_trusted: bool) -> Option<AtCores> {
    let trusted = trusted(at);
    Some(AtCores {
        cores,
        oversubscribed: at.iter().any(|(_, b)| b.oversubscribed),
        contended: at.len() - trusted.len(),
        // At one core the speedups have a finding of their own.
        show_speedup: cores > 1 && seq_trusted,
        verdict: verdict(&trusted)?,
    })
}

/// Per chunked series whose best cells were confirmed: each best cell against the grid's
/// runner-up at its core count, both measured without contention.
fn best_chunks(view: &GroupView, bests: &[(SeriesKey, Vec<Best>)]) -> Vec<Finding> {
    bests
        .iter()
        .map(|(_, best)| {
            best.iter()
                .filter(|b| calm(b))
                .filter_map(|b| Some((b.clone(), view.runner_up(b).filter(calm)?)))
                .collect::<Vec<_>>()
        })
        .filter(|pairs| !pairs.is_empty())
        .map(Finding::BestChunks)
        .collect()
}

/// Where more chunks stop paying, per chunked series.
fn chunking(view: &GroupView, bests: &[(SeriesKey, Vec<Best>)]) -> Vec<Finding> {
    bests
        .iter()
        .filter(|(k, _)| select::is_chunked(&view.rows, &view.group, k.strategy))
        .filter_map(|&(key, _)| {
            let from: Vec<(usize, usize)> = series::chunk_table(view, key)
                .iter()
                .filter(|(_, v)| v.len() > 1)
                .filter_map(|(c, v)| Some((series::chunking_stops_paying(v)?, *c)))
                .collect();
            (!from.is_empty()).then_some(Finding::ChunkingStops { series: key, from })
        })
        .collect()
}

/// The serial fraction of the fastest trusted cell at the most cores not oversubscribed,
/// among those whose serial fraction has an interval above 0.
fn karp_flatt(bests: &[(SeriesKey, Vec<Best>)]) -> Option<Finding> {
    let (best, (e, ci)) = bests
        .iter()
        .flat_map(|(_, b)| b)
        .filter(|b| !b.oversubscribed && calm(b))
        .filter_map(|b| Some((b, b.serial_fraction()?)))
        .max_by(|a, b| {
            a.0.cores
                .cmp(&b.0.cores)
                .then(b.0.mean_s.total_cmp(&a.0.mean_s))
        })?;
    Some(Finding::SerialFraction {
        best: best.clone(),
        e,
        ci,
    })
}

/// The paper's published speedups beside ours, where comparable.
fn against_paper(view: &GroupView, bests: &[(SeriesKey, Vec<Best>)]) -> Option<Finding> {
    if !paper::comparable(&view.group) {
        return None;
    }
    let points: Vec<PaperPoint> = view
        .cores()
        .into_iter()
        .filter_map(|c| {
            let p = paper::at(c)?;
            let best = bests
                .iter()
                .filter_map(|(_, b)| b.iter().find(|b| b.cores == c && calm(b)))
                .filter(|b| b.speedup.is_some())
                .max_by(|a, b| {
                    a.speedup
                        .unwrap_or(0.0)
                        .total_cmp(&b.speedup.unwrap_or(0.0))
                })?;
            Some(PaperPoint {
                best: best.clone(),
                paper: p.speedup,
            })
        })
        .collect();
    (!points.is_empty()).then_some(Finding::AgainstPaper(points))
}

impl Finding {
    /// The finding in one sentence (Markdown).
    pub fn sentence(&self) -> String {
        match self {
            Finding::Withheld(why) => why.sentence(),
            Finding::ContendedReference => "The seq reference was contended (other work used \
                the machine while it ran): no speedup, serial fraction or comparison with the \
                paper is given as a finding."
                .to_owned(),
            Finding::AtCores(at) => at.sentence(),
            Finding::OneCore(cells) => one_core(cells),
            Finding::Placements(p) => p.sentence(),
            Finding::BestChunks(pairs) => {
                let parts: Vec<String> = pairs
                    .iter()
                    .map(|(b, up)| {
                        let chunks = |b: &Best| format!("{} chunks", b.chunks.unwrap_or(1));
                        let (these, those) = (chunks(b), chunks(up));
                        let said = match order(b, up) {
                            Order::AFaster(r) | Order::BFaster(r) => {
                                format!("{these} is {}", faster(&r, &those))
                            }
                            Order::Unresolved(r) => format!(
                                "{these} and {those} are not distinguishable ({})",
                                plus_minus(r.value, r.interval)
                            ),
                            Order::Unknown(_) => format!("{these} against {those}: no interval"),
                        };
                        format!("at {} {said}", series::cores_label(b.cores))
                    })
                    .collect();
                format!(
                    "{}: the grid's best chunks against its runner-up, both measured again in \
                     the confirmation rounds: {}.",
                    pairs[0].0.key(),
                    parts.join("; ")
                )
            }
            Finding::ChunkingStops {
                series: strategy,
                from,
            } => {
                let parts: Vec<String> = from
                    .iter()
                    .map(|(k, c)| format!("{k} chunks at {}", series::cores_label(*c)))
                    .collect();
                format!(
                    "{strategy}: more chunks stop paying (no larger chunk count is faster by \
                     the grid's paired rounds) from {}.",
                    parts.join(", ")
                )
            }
            Finding::SerialFraction { best, e, ci } => format!(
                "Karp–Flatt serial fraction of {} at {} (speedup {}): e = {}{}. It describes \
                 the runs measured here; from so few core counts it forecasts nothing about \
                 more cores.",
                best.key(),
                series::cores_label(best.cores),
                plus_minus(best.speedup.unwrap_or(f64::NAN), best.speedup_ci),
                sig(*e),
                interval(Some(*ci))
            ),
            Finding::RankShift(shift) => shift.sentence(),
            Finding::AgainstPaper(points) => format!(
                "Against the paper's published speedups (its machine, its program): {}.",
                points
                    .iter()
                    .map(PaperPoint::phrase)
                    .collect::<Vec<_>>()
                    .join("; ")
            ),
        }
    }
}

/// The one-core finding: who is faster or slower than `seq` in the same rounds, and who is not
/// distinguishable from it.
fn one_core(cells: &[Best]) -> String {
    let mut resolved = Vec::new();
    let mut not = Vec::new();
    for b in cells {
        let Some(r) = speedup(b).filter(|r| r.interval.is_some()) else {
            continue;
        };
        if r.resolved() {
            resolved.push(format!("{} is {}", named(b), faster(&r, "seq")));
        } else {
            not.push(format!(
                "{} ({})",
                named(b),
                plus_minus(r.value, r.interval)
            ));
        }
    }
    let mut parts = Vec::new();
    if !resolved.is_empty() {
        parts.push(format!(
            "{} (its own cost or gain on one thread: the 95 % interval of the paired speedup \
             excludes 1)",
            and_list(&resolved)
        ));
    }
    if !not.is_empty() {
        parts.push(format!("not distinguishable from seq: {}", and_list(&not)));
    }
    format!(
        "At 1 core, where every strategy does seq's work, against seq in the same rounds: {}.",
        parts.join("; ")
    )
}

impl Withheld {
    fn sentence(self) -> String {
        match self {
            Withheld::Design(Design::BeforeRounds) => "Findings withheld: this sweep was \
                measured before rounds (each cell's trials back to back, bootstrap intervals \
                that under-cover, speedups that divide two means), so no comparison can be \
                trusted to reproduce. The tables show what was measured."
                .to_owned(),
            Withheld::Design(_) => "Findings withheld: this sweep ran each cell's runs back to \
                back (`--schedule cells`), so runs of one round are minutes apart and pairing \
                them does not cancel the machine's drift. The tables show what was measured."
                .to_owned(),
            Withheld::Unchecked => "Findings withheld: this group's directory has no \
                trials.csv, so its statistics could not be checked against the runs (summary.csv \
                alone is taken on trust) and no two cells' runs can be paired. The tables show \
                what summary.csv says."
                .to_owned(),
            Withheld::Rounds(k) => format!(
                "No finding: these cells ran {}, and an interval, so a finding, needs \
                 {MIN_ROUNDS} or more (`--trials {MIN_ROUNDS}`).",
                sph_harness::output::console::plural(k, "round", "rounds")
            ),
        }
    }
}

impl PaperPoint {
    fn phrase(&self) -> String {
        let b = &self.best;
        format!(
            "at {}{} the best here is {} ({}) against the paper's {}×",
            series::cores_label(b.cores),
            if b.oversubscribed {
                " (⚠ oversubscribed here)"
            } else {
                ""
            },
            plus_minus(b.speedup.unwrap_or(f64::NAN), b.speedup_ci),
            b.key(),
            sig(self.paper)
        )
    }
}

impl AtCores {
    /// Who is fastest, as a sentence: one per verdict.
    fn sentence(&self) -> String {
        let left_out = match self.contended {
            0 => String::new(),
            1 => " (1 contended cell left out)".to_owned(),
            k => format!(" ({k} contended cells left out)"),
        };
        let where_ = format!(
            "At {}{}",
            series::cores_label(self.cores),
            if self.oversubscribed {
                " (⚠ oversubscribed: more threads than the machine has)"
            } else {
                ""
            }
        );
        match &self.verdict {
            Verdict::Only(w) => {
                let only = if self.contended > 0 {
                    "was measured without contention"
                } else {
                    "was measured"
                };
                format!("{where_}, only {} {only}{left_out}.", describe(w))
            }
            Verdict::Unknown { lowest: w, why, .. } => format!(
                "{where_}, the lowest mean is {}, but {}, so no strategy can be called \
                 fastest{left_out}.",
                describe(w),
                why.phrase()
            ),
            Verdict::Fastest {
                winner,
                runner_up,
                by,
            } => {
                let speed = speedup(&winner.1)
                    .filter(|_| self.show_speedup)
                    .map_or_else(String::new, |s| {
                        format!(", {} over seq", plus_minus(s.value, s.interval))
                    });
                format!(
                    "{where_}, **{}** is fastest{speed}: it is {} by the paired rounds (95 % \
                     interval excluding 1){left_out}.",
                    describe(winner),
                    faster(by, &format!("the runner-up {}", describe(runner_up)))
                )
            }
            Verdict::Tied { tied, slower } => format!(
                "{where_}, {} are not distinguishable (the 95 % interval of each one's time \
                 ratio to the lowest mean, paired by round, contains 1){}{left_out}.",
                and_list(&tied.iter().map(describe).collect::<Vec<_>>()),
                match slower {
                    0 => String::new(),
                    1 => "; the other strategy is slower".to_owned(),
                    _ => "; the others are slower".to_owned(),
                }
            ),
        }
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::report::view::tests::{Spec, measured, view, with_trials};
    use sph_harness::results::rows::Phase;
    use sph_harness::topology::Pin;
    use sph_strategies::StrategyName::{RayonChunks, RayonIter, Seq};

    const NONE: Pin = Pin::None;
    /// seq's times per round: the machine drifts from round to round.
    pub(crate) const SEQ: [f64; 3] = [4.0, 4.8, 3.2];

    fn said(v: &GroupView) -> Vec<String> {
        findings(v).iter().map(Finding::sentence).collect()
    }

    fn sentences(specs: &[Spec<'_>]) -> Vec<String> {
        said(&view(specs))
    }

    #[test]
    fn a_strategy_is_faster_only_where_its_paired_interval_excludes_one() {
        // rayon-iter takes 5 % longer than rayon-chunks in every round, though the drift
        // makes each one's own interval far wider than 5 %: paired, the order is resolved.
        let f = sentences(&[
            (Seq, 1, None, NONE, &SEQ),
            (RayonChunks, 2, Some(10), NONE, &[2.0, 2.4, 1.6]),
            (RayonIter, 2, None, NONE, &[2.1, 2.52, 1.68]),
        ]);
        assert!(
            f[0].starts_with("At 2 cores, **rayon-chunks with 10 chunks (2.00 s [")
                && f[0].contains("** is fastest, 2.00 ± 0.00× over seq: it is 1.05 ± 0.00× faster than the runner-up rayon-iter (2.10 s ["),
            "{}",
            f[0]
        );
        // The same means, but rounds that disagree: not distinguishable.
        let f = sentences(&[
            (Seq, 1, None, NONE, &SEQ),
            (RayonChunks, 2, Some(10), NONE, &[2.0, 2.4, 1.6]),
            (RayonIter, 2, None, NONE, &[2.3, 2.2, 1.8]),
        ]);
        assert!(
            f[0].contains("are not distinguishable") && !f[0].contains("fastest"),
            "{}",
            f[0]
        );
    }

    #[test]
    fn fewer_than_three_rounds_give_no_finding_and_say_so() {
        let f = sentences(&[
            (Seq, 1, None, NONE, &[4.0, 4.0]),
            (RayonChunks, 2, Some(10), NONE, &[2.0, 2.0]),
            (RayonIter, 2, None, NONE, &[3.0, 3.0]),
        ]);
        assert_eq!(
            f,
            [
                "No finding: these cells ran 2 rounds, and an interval, so a finding, needs 3 \
              or more (`--trials 3`)."
            ]
        );
    }

    #[test]
    fn contended_cells_enter_no_finding() {
        let (mut rows, trials) = measured(
            &[
                (Seq, 1, None, NONE, &SEQ),
                (RayonChunks, 2, Some(10), NONE, &[2.0, 2.4, 1.6]),
                (RayonIter, 2, None, NONE, &[1.0, 1.2, 0.8]),
            ],
            Phase::Grid,
        );
        rows[2].contended = Some(true);
        let f = said(&with_trials(rows, trials));
        assert!(
            f[0].contains("only rayon-chunks") && f[0].contains("1 contended cell left out"),
            "{}",
            f[0]
        );
    }

    #[test]
    fn a_one_core_speedup_whose_interval_excludes_one_is_a_finding_about_the_strategy() {
        let f = sentences(&[
            (Seq, 1, None, NONE, &SEQ),
            (RayonChunks, 1, Some(10), NONE, &[4.4, 5.28, 3.52]),
            (RayonIter, 1, None, NONE, &[3.9, 4.9, 3.3]),
            (RayonChunks, 2, Some(10), NONE, &[2.2, 2.64, 1.76]),
        ])
        .join("\n");
        assert!(
            f.contains(
                "At 1 core, where every strategy does seq's work, against seq in the same \
                 rounds: rayon-chunks with 10 chunks is 1.10 ± 0.00× slower than seq (its own \
                 cost or gain on one thread: the 95 % interval of the paired speedup excludes \
                 1); not distinguishable from seq: rayon-iter (0.991 ± 0.076×)."
            ),
            "{f}"
        );
        assert!(!f.contains("noise"), "{f}");
    }

    #[test]
    fn karp_flatt_comes_with_its_interval_and_not_where_that_interval_reaches_zero() {
        // Speedup 1.6 at 2 cores, the same in every round: e = 0.25, its interval a point.
        let f = sentences(&[
            (Seq, 1, None, NONE, &SEQ),
            (RayonChunks, 2, Some(10), NONE, &[2.5, 3.0, 2.0]),
        ])
        .join("\n");
        assert!(
            f.contains("(speedup 1.60 ± 0.00×): e = 0.250 [0.250–0.250]"),
            "{f}"
        );
        // Speedups of 1.9 to 2.1 by round: the interval of e reaches below 0.
        let f = sentences(&[
            (Seq, 1, None, NONE, &SEQ),
            (
                RayonChunks,
                2,
                Some(10),
                NONE,
                &[4.0 / 1.9, 4.8 / 2.1, 3.2 / 1.95],
            ),
        ])
        .join("\n");
        assert!(!f.contains("Karp–Flatt"), "{f}");
    }

    #[test]
    fn a_contended_reference_gives_no_speedup_finding() {
        let (mut rows, trials) = measured(
            &[
                (Seq, 1, None, NONE, &SEQ),
                (RayonChunks, 2, Some(10), NONE, &[2.5, 3.0, 2.0]),
            ],
            Phase::Grid,
        );
        rows[0].contended = Some(true);
        let f = said(&with_trials(rows, trials));
        let f = f.join("\n");
        assert!(f.contains("The seq reference was contended"), "{f}");
        assert!(!f.contains("Karp–Flatt") && !f.contains("over seq"), "{f}");
        assert!(!f.contains("paper's"), "{f}");
    }

    #[test]
    fn a_sweep_whose_rounds_do_not_pair_gets_no_finding() {
        let mut v = view(&[
            (Seq, 1, None, NONE, &SEQ),
            (RayonChunks, 2, Some(10), NONE, &[2.5, 3.0, 2.0]),
        ]);
        v.design = Design::BeforeRounds;
        let f = said(&v);
        assert_eq!(f.len(), 1);
        assert!(f[0].starts_with("Findings withheld: this sweep was measured before rounds"));
    }

    #[test]
    fn a_placement_is_faster_only_where_the_paired_rounds_resolve_it_and_named_wherever_a_cell_is()
    {
        let (none, spread) = (Pin::None, Pin::Spread);
        let f = sentences(&[
            (Seq, 1, None, none, &SEQ),
            (RayonChunks, 1, Some(10), none, &[3.9, 4.9, 3.3]),
            (RayonChunks, 1, Some(10), spread, &[4.0, 4.7, 3.3]),
            (RayonChunks, 2, Some(10), none, &[2.2, 2.64, 1.76]),
            (RayonChunks, 2, Some(10), spread, &[1.8, 2.16, 1.44]),
            // Spread's 5 chunks have no unpinned twin: not compared, though faster.
            (RayonChunks, 2, Some(5), spread, &[1.0, 1.2, 0.8]),
        ]);
        let compared = |s: &&String| s.contains("` against ");
        let s = f.iter().find(compared).unwrap();
        assert_eq!(
            s,
            "rayon-chunks, `spread` against unpinned (at each core count, the chunks value \
             fastest under either): `spread` is faster (paired rounds) at 2 cores; they are \
             not distinguishable at 1 core; the largest difference is at 2 cores with 10 \
             chunks: `spread` 2.22 ± 0.00× against unpinned 1.82 ± 0.00× over seq."
        );
        assert_eq!(f.iter().filter(compared).count(), 1, "{f:#?}");
        assert!(
            f.iter().any(|s| s
                == "rayon-chunks (spread): more chunks stop paying (no larger chunk count is \
                    faster by the grid's paired rounds) from 5 chunks at 2 cores."),
            "{f:#?}"
        );
        // Pinned cells are named as such wherever a finding names a cell.
        assert!(
            f.iter()
                .any(|s| s.contains("**rayon-chunks (spread) with 5 chunks (1.00 s")),
            "{f:?}"
        );
    }
}
