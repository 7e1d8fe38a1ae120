//! The findings of a group: sentences that never claim more than the data shows.
//!
//! - A strategy is called **fastest** at a core count only when its 95 % interval of the mean
//!   does not overlap any other strategy's; otherwise the strategies whose intervals overlap
//!   the fastest mean's are named as **indistinguishable within the trial spread**.
//! - Contended cells (other work used the machine, or passes ran alone) enter no finding; the
//!   sentence says how
//!   many were left out.
//! - A speedup above 1 at one core is labelled noise in the reference, never a win.
//! - The Karp–Flatt serial fraction is given only where the speedup is above 1 on at least 2
//!   cores, as a measurement at that core count, never extrapolated.
//! - Each strategy at each placement (`sweep --pin`) is a series of its own
//!   ([`series::SeriesKey`]), named `rayon-chunks (spread)` where pinned. Two placements of a
//!   strategy are compared cell against cell, at the same cores and chunks ([`super::placements`]):
//!   one is called faster at a core count only where their 95 % intervals of the mean are
//!   apart, and each strategy gets one sentence per pair of placements, not one per cell.
//!
//! - Across workloads ([`super::rank_shift`]: the toy Müller model against wcsph at one core count),
//!   a winner is named only when its interval overlaps no other's on both; a strategy has
//!   moved up or down only when it passed another whose intervals are apart on both
//!   workloads; any other change of place is said to be not resolved.
//!
//! [`findings`] decides what the data supports, as [`Finding`] values; [`Finding::sentence`]
//! words each one.

use super::numbers::{interval, percent, secs, times};
use super::paper;
use super::placements::{Placements, pin_name};
use super::rank_shift::RankShift;
use super::series::{self, Best, Group, SeriesKey};
use crate::results::rows::SummaryRow;
use crate::results::stats::Interval;
use crate::topology::Pin;
use sph_strategies::StrategyName;

/// What the data of a group supports, decided before it is worded.
#[derive(Debug, Clone, PartialEq)]
pub enum Finding {
    /// The group's `seq` reference was contended: no speedup-based finding follows.
    ContendedReference,
    /// Who is fastest at one core count, if anyone can be said to be.
    AtCores(AtCores),
    /// A speedup above 1 at one core: the reference's noise, not a win.
    OneCoreNoise {
        /// The strategy.
        strategy: StrategyName,
        /// Per placement with such a speedup (in the order of [`series::pins`]): the
        /// placement, its speedup at 1 core and the speedup's 95 % interval.
        speedups: Vec<(Pin, f64, Option<Interval>)>,
    },
    /// Two placements of a strategy, compared where both were measured.
    Placements(Placements),
    /// Where more chunks stop paying for a chunked strategy.
    ChunkingStops {
        /// The strategy, at one placement.
        series: SeriesKey,
        /// (chunks from which more stop paying, at this many cores), by cores.
        from: Vec<(usize, usize)>,
    },
    /// The Karp–Flatt serial fraction of the fastest trusted cell at the most cores.
    SerialFraction {
        /// The strategy.
        strategy: StrategyName,
        /// Its cell.
        best: Best,
        /// The serial fraction e.
        e: f64,
    },
    /// The paper's published speedups beside the best here, per comparable core count.
    AgainstPaper(Vec<PaperPoint>),
    /// How the strategy ranking changes from the toy workload to wcsph at one core count
    /// (boxed: it is the largest finding by far).
    RankShift(Box<RankShift>),
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
    /// Worker threads.
    pub cores: usize,
    /// The best cell here was oversubscribed.
    pub oversubscribed: bool,
    /// The best speedup here.
    pub speedup: f64,
    /// Its strategy.
    pub strategy: StrategyName,
    /// The paper's speedup at these cores.
    pub paper: f64,
    /// Where its threads ran.
    pub pin: Pin,
}

/// The findings for group `g` of `rows`.
pub fn findings(rows: &[SummaryRow], g: &Group) -> Vec<Finding> {
    let strategies: Vec<StrategyName> = series::strategies(rows, g)
        .into_iter()
        .filter(|&s| s != StrategyName::Seq)
        .collect();
    let bests: Vec<(StrategyName, Vec<Best>)> = series::series(rows, g)
        .into_iter()
        .map(|key| (key.strategy, series::best_per_cores(rows, g, key)))
        .collect();
    // A contended reference makes every speedup doubtful: none enters a finding then.
    let seq_trusted = !rows
        .iter()
        .any(|r| r.group() == *g && r.is_reference() && r.contended == Some(true));
    let mut out = Vec::new();
    if !seq_trusted {
        out.push(Finding::ContendedReference);
    }
    for c in series::cores(rows, g) {
        let at: Vec<Entry> = bests
            .iter()
            .filter_map(|(s, b)| Some((*s, b.iter().find(|b| b.cores == c)?.clone())))
            .collect();
        out.extend(at_cores(c, &at, seq_trusted).map(Finding::AtCores));
        if c == 1 && seq_trusted {
            out.extend(one_core_noise(&at));
        }
    }
    out.extend(
        super::placements::compare(rows, g, &strategies, seq_trusted).map(Finding::Placements),
    );
    out.extend(chunking(rows, g, &strategies));
    if seq_trusted {
        out.extend(karp_flatt(&bests));
        out.extend(against_paper(rows, g, &bests));
    }
    out
}

/// A strategy's best cell at one core count.
pub type Entry = (StrategyName, Best);

/// What can be said about the fastest strategy at one core count, from the cells measured
/// without contention (fastest first).
#[derive(Debug, Clone, PartialEq)]
pub enum Verdict {
    /// Only one cell.
    Only(Entry),
    /// Several, but some without confidence intervals: the lowest mean only.
    NoIntervals(Entry),
    /// The fastest cell's interval overlaps no other's.
    Fastest {
        /// The fastest.
        winner: Entry,
        /// The second fastest.
        runner_up: Entry,
    },
    /// The fastest cell's interval overlaps these (the fastest first).
    Tied {
        /// The cells whose intervals overlap the fastest one's, and it.
        tied: Vec<Entry>,
        /// How many are slower beyond the overlap.
        slower: usize,
    },
}

/// The verdict on `trusted` (sorted fastest first); `None` when it is empty.
pub fn verdict(trusted: &[Entry]) -> Option<Verdict> {
    let first = trusted.first()?.clone();
    if trusted.len() == 1 {
        return Some(Verdict::Only(first));
    }
    if trusted.iter().any(|(_, b)| b.mean_ci.is_none()) {
        return Some(Verdict::NoIntervals(first));
    }
    let mut tied = vec![first.clone()];
    tied.extend(
        trusted[1..]
            .iter()
            .filter(|(_, b)| match (first.1.mean_ci, b.mean_ci) {
                (Some(a), Some(o)) => a.overlaps(&o),
                _ => true,
            })
            .cloned(),
    );
    Some(if tied.len() == 1 {
        Verdict::Fastest {
            winner: first,
            runner_up: trusted[1].clone(),
        }
    } else {
        let slower = trusted.len() - tied.len();
        Verdict::Tied { tied, slower }
    })
}

/// The cells of `at` measured without contention, fastest first (the first of equal means).
pub(super) fn trusted(at: &[Entry]) -> Vec<Entry> {
    let mut trusted: Vec<Entry> = at.iter().filter(|(_, b)| !b.contended).cloned().collect();
    trusted.sort_by(|a, b| a.1.mean_s.total_cmp(&b.1.mean_s));
    trusted
}

/// The verdict at `cores` on the cells `at`, the contended ones left out.
fn at_cores(cores: usize, at: &[Entry], seq_trusted: bool) -> Option<AtCores> {
    let trusted = trusted(at);
    Some(AtCores {
        cores,
        oversubscribed: at.iter().any(|(_, b)| b.oversubscribed),
        contended: at.len() - trusted.len(),
        // At one core a speedup is the reference's noise (said separately), not a result.
        show_speedup: cores > 1 && seq_trusted,
        verdict: verdict(&trusted)?,
    })
}

/// Whether two cells' 95 % intervals are apart (both known and not overlapping).
pub(super) fn apart(a: &Best, b: &Best) -> bool {
    match (a.mean_ci, b.mean_ci) {
        (Some(x), Some(y)) => !x.overlaps(&y),
        _ => false,
    }
}

/// A speedup above 1 at one core is the reference's noise: one finding per strategy, over
/// its placements (`at` holds a strategy's series in the order of [`series::series`]).
fn one_core_noise(at: &[Entry]) -> Vec<Finding> {
    let mut out: Vec<Finding> = Vec::new();
    for (s, b) in at.iter().filter(|(_, b)| !b.contended) {
        let Some(speedup) = b.speedup.filter(|&sp| sp > 1.0) else {
            continue;
        };
        let one = (b.pin, speedup, b.speedup_ci);
        match out.last_mut() {
            Some(Finding::OneCoreNoise { strategy, speedups }) if strategy == s => {
                speedups.push(one);
            }
            _ => out.push(Finding::OneCoreNoise {
                strategy: *s,
                speedups: vec![one],
            }),
        }
    }
    out
}

/// Where more chunks stop paying, per chunked strategy at each of its placements.
fn chunking(rows: &[SummaryRow], g: &Group, strategies: &[StrategyName]) -> Vec<Finding> {
    let mut out = Vec::new();
    for &s in strategies
        .iter()
        .filter(|&&s| series::is_chunked(rows, g, s))
    {
        for key in series::pins(rows, g, s)
            .into_iter()
            .map(|p| SeriesKey::new(s, p))
        {
            let from: Vec<(usize, usize)> = series::chunk_table(rows, g, key)
                .iter()
                .filter(|(_, v)| v.len() > 1)
                .filter_map(|(c, v)| Some((series::chunking_stops_paying(v)?, *c)))
                .collect();
            if !from.is_empty() {
                out.push(Finding::ChunkingStops { series: key, from });
            }
        }
    }
    out
}

/// The serial fraction of the fastest trusted cell at the most cores not oversubscribed,
/// where it means something.
fn karp_flatt(bests: &[(StrategyName, Vec<Best>)]) -> Option<Finding> {
    let (s, b) = bests
        .iter()
        .flat_map(|(s, b)| b.iter().map(move |b| (*s, b)))
        .filter(|(_, b)| b.cores > 1 && !b.oversubscribed && !b.contended)
        .filter(|(_, b)| b.speedup.is_some_and(|sp| sp > 1.0))
        .max_by(|a, b| {
            a.1.cores
                .cmp(&b.1.cores)
                .then(b.1.mean_s.total_cmp(&a.1.mean_s))
        })?;
    Some(Finding::SerialFraction {
        strategy: s,
        e: b.serial_fraction()?,
        best: b.clone(),
    })
}

/// The paper's published speedups beside ours, where comparable.
fn against_paper(
    rows: &[SummaryRow],
    g: &Group,
    bests: &[(StrategyName, Vec<Best>)],
) -> Option<Finding> {
    if !paper::comparable(g) {
        return None;
    }
    let mut points = Vec::new();
    for c in series::cores(rows, g) {
        let Some(p) = paper::at(c) else { continue };
        let best = bests
            .iter()
            .filter_map(|(s, b)| Some((*s, b.iter().find(|b| b.cores == c)?)))
            .filter(|(_, b)| !b.contended)
            .filter_map(|(s, b)| Some((s, b.speedup?, b.oversubscribed, b.pin)))
            .max_by(|a, b| a.1.total_cmp(&b.1));
        if let Some((strategy, speedup, oversubscribed, pin)) = best {
            points.push(PaperPoint {
                cores: c,
                oversubscribed,
                speedup,
                strategy,
                paper: p.speedup,
                pin,
            });
        }
    }
    (!points.is_empty()).then_some(Finding::AgainstPaper(points))
}

impl Finding {
    /// The finding in one sentence (Markdown).
    pub fn sentence(&self) -> String {
        match self {
            Finding::ContendedReference => "The seq reference was contended (other work used \
                the machine while it ran): no speedup, serial fraction or comparison with the \
                paper is given as a finding."
                .to_owned(),
            Finding::AtCores(at) => at.sentence(),
            Finding::OneCoreNoise { strategy, speedups } => match speedups.as_slice() {
                [(pin, speedup, ci)] => format!(
                    "{}'s speedup of {}{} at 1 core is noise in the seq reference, not a win: \
                     one worker runs the same passes as seq.",
                    SeriesKey::new(*strategy, *pin),
                    times(*speedup),
                    interval(*ci)
                ),
                several => format!(
                    "{strategy}'s speedups of {} at 1 core are noise in the seq reference, not \
                     a win: one worker runs the same passes as seq.",
                    and_list(
                        &several
                            .iter()
                            .map(|(pin, speedup, ci)| format!(
                                "{}{} ({})",
                                times(*speedup),
                                interval(*ci),
                                pin_name(*pin)
                            ))
                            .collect::<Vec<_>>()
                    )
                ),
            },
            Finding::Placements(p) => p.sentence(),
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
                     more than the trial spread) from {}.",
                    parts.join(", ")
                )
            }
            Finding::SerialFraction { strategy, best, e } => format!(
                "Karp–Flatt serial fraction of {} at {} ({}{}): e = {}. It describes \
                 the runs measured here; from so few core counts it forecasts nothing about \
                 more cores.",
                SeriesKey::new(*strategy, best.pin),
                series::cores_label(best.cores),
                times(best.speedup.unwrap_or(f64::NAN)),
                interval(best.speedup_ci),
                super::numbers::sig(*e)
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

impl PaperPoint {
    fn phrase(&self) -> String {
        format!(
            "at {}{} the best here is {} ({}) against the paper's {}",
            series::cores_label(self.cores),
            if self.oversubscribed {
                " (⚠ oversubscribed here)"
            } else {
                ""
            },
            times(self.speedup),
            SeriesKey::new(self.strategy, self.pin),
            times(self.paper)
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
            Verdict::NoIntervals(w) => format!(
                "{where_}, the lowest mean is {}, but these cells have no confidence intervals \
                 (one trial, or a sweep older than them), so no strategy can be called \
                 fastest{left_out}.",
                describe(w)
            ),
            Verdict::Fastest { winner, runner_up } => {
                let (wb, rb) = (&winner.1, &runner_up.1);
                let speed = wb
                    .speedup
                    .filter(|_| self.show_speedup)
                    .map_or_else(String::new, |s| {
                        format!(", {}{} over seq", times(s), interval(wb.speedup_ci))
                    });
                format!(
                    "{where_}, **{}** is fastest{speed}; its 95 % interval does not overlap the \
                     runner-up {}, which takes {} more time{left_out}.",
                    describe(winner),
                    describe(runner_up),
                    percent((rb.mean_s - wb.mean_s) / wb.mean_s * 100.0)
                )
            }
            Verdict::Tied { tied, slower } => format!(
                "{where_}, {} are indistinguishable within the trial spread (their 95 % \
                 intervals overlap){}{left_out}.",
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

/// A verdict in a few words, strategies by name only (the table beside it has the numbers).
pub(super) fn verdict_phrase(v: Option<&Verdict>) -> String {
    match v {
        None => "no cell was measured without contention".to_owned(),
        Some(Verdict::Only((s, _))) => format!("only {s} was measured"),
        Some(Verdict::NoIntervals((s, _))) => format!(
            "the lowest mean is {s}'s, but without confidence intervals no strategy can be \
             called fastest"
        ),
        Some(Verdict::Fastest { winner, .. }) => format!("**{}** is fastest", winner.0),
        Some(Verdict::Tied { tied, .. }) => format!(
            "{} are indistinguishable within the trial spread (their 95 % intervals overlap)",
            names(&tied.iter().map(|(s, _)| *s).collect::<Vec<_>>())
        ),
    }
}

/// Strategy names as `a`, `a and b`, `a, b and c`.
pub(super) fn names(strategies: &[StrategyName]) -> String {
    and_list(&strategies.iter().map(|s| s.to_string()).collect::<Vec<_>>())
}

/// A cell as findings name it: `rayon-chunks with 45 chunks (0.412 s [0.40, 0.42])`, or
/// pinned, `rayon-chunks (spread) with 45 chunks (…)`.
pub(super) fn describe((s, b): &Entry) -> String {
    format!(
        "{}{} ({} s{})",
        SeriesKey::new(*s, b.pin),
        b.chunks
            .map_or_else(String::new, |k| format!(" with {k} chunks")),
        secs(b.mean_s),
        interval(b.mean_ci)
    )
}

/// `a`, `a and b`, `a, b and c`.
pub(super) fn and_list(items: &[String]) -> String {
    match items {
        [] => String::new(),
        [one] => one.clone(),
        [init @ .., last] => format!("{} and {last}", init.join(", ")),
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::results::rows::tests::row;

    fn sentences(rows: &[SummaryRow], g: &Group) -> Vec<String> {
        findings(rows, g).iter().map(Finding::sentence).collect()
    }

    pub(crate) fn with_ci(mut r: SummaryRow, low: f64, high: f64) -> SummaryRow {
        r.mean_ci_low_s = Some(low);
        r.mean_ci_high_s = Some(high);
        r
    }

    #[test]
    fn overlapping_intervals_name_no_winner() {
        let rows = vec![
            row(StrategyName::Seq, 1, None, 4.0),
            with_ci(row(StrategyName::RayonChunks, 2, Some(10), 2.2), 2.0, 2.4),
            with_ci(row(StrategyName::RayonIter, 2, None, 2.3), 2.1, 2.5),
        ];
        let f = sentences(&rows, &rows[0].group());
        assert!(
            f[0].contains("indistinguishable within the trial spread") && !f[0].contains("fastest"),
            "{}",
            f[0]
        );
    }

    #[test]
    fn separate_intervals_name_the_fastest_with_its_margin() {
        let rows = vec![
            row(StrategyName::Seq, 1, None, 4.0),
            with_ci(row(StrategyName::RayonChunks, 2, Some(10), 2.2), 2.1, 2.3),
            with_ci(row(StrategyName::RayonIter, 2, None, 2.6), 2.5, 2.7),
        ];
        let f = sentences(&rows, &rows[0].group());
        assert!(
            f[0].starts_with(
                "At 2 cores, **rayon-chunks with 10 chunks (2.20 s [2.10–2.30])** is fastest"
            ),
            "{}",
            f[0]
        );
        assert!(f[0].contains("18.2 % more time"), "{}", f[0]);
    }

    #[test]
    fn contended_cells_enter_no_finding() {
        let mut fast = with_ci(row(StrategyName::RayonIter, 2, None, 1.0), 0.9, 1.1);
        fast.contended = Some(true);
        let rows = vec![
            row(StrategyName::Seq, 1, None, 4.0),
            with_ci(row(StrategyName::RayonChunks, 2, Some(10), 2.2), 2.1, 2.3),
            fast,
        ];
        let f = sentences(&rows, &rows[0].group());
        assert!(
            f[0].contains("only rayon-chunks") && f[0].contains("1 contended cell left out"),
            "{}",
            f[0]
        );
    }

    #[test]
    fn a_one_core_speedup_above_one_is_called_noise_and_karp_flatt_never_extrapolates() {
        let rows = vec![
            row(StrategyName::Seq, 1, None, 4.0),
            row(StrategyName::RayonChunks, 1, Some(10), 3.9),
            row(StrategyName::RayonChunks, 2, Some(10), 2.2),
        ];
        let f = sentences(&rows, &rows[0].group()).join("\n");
        assert!(f.contains("at 1 core is noise in the seq reference"), "{f}");
        assert!(f.contains("e = 0.100"), "{f}");
        assert!(!f.contains("no number of cores"), "{f}");
    }

    #[test]
    fn a_contended_reference_gives_no_speedup_finding() {
        let mut seq = row(StrategyName::Seq, 1, None, 4.0);
        seq.contended = Some(true);
        let rows = vec![seq, row(StrategyName::RayonChunks, 2, Some(10), 2.2)];
        let f = sentences(&rows, &rows[0].group()).join("\n");
        assert!(f.contains("The seq reference was contended"), "{f}");
        assert!(!f.contains("Karp–Flatt") && !f.contains("over seq"), "{f}");
        assert!(!f.contains("paper's"), "{f}");
    }

    #[test]
    fn no_karp_flatt_without_a_speedup_above_one() {
        let rows = vec![
            row(StrategyName::Seq, 1, None, 4.0),
            row(StrategyName::RayonIter, 2, None, 5.0),
        ];
        let f = sentences(&rows, &rows[0].group()).join("\n");
        assert!(!f.contains("Karp–Flatt"), "{f}");
    }
}
