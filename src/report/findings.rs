//! The findings of a group: sentences that never claim more than the data shows.
//!
//! - A strategy is called **fastest** at a core count only when its 95 % interval of the mean
//!   does not overlap any other strategy's; otherwise the strategies whose intervals overlap
//!   the fastest mean's are named as **indistinguishable within the trial spread**.
//! - Contended cells (other work used the machine) enter no finding; the sentence says how
//!   many were left out.
//! - A speedup above 1 at one core is labelled noise in the reference, never a win.
//! - The Karp–Flatt serial fraction is given only where the speedup is above 1 on at least 2
//!   cores, as a measurement at that core count, never extrapolated.

use super::numbers::{interval, percent, secs, times};
use super::paper;
use super::series::{self, Best, Group};
use crate::results::rows::SummaryRow;
use sph_strategies::StrategyName;

/// The sentences for group `g` of `rows`.
pub fn findings(rows: &[SummaryRow], g: &Group) -> Vec<String> {
    let strategies: Vec<StrategyName> = series::strategies(rows, g)
        .into_iter()
        .filter(|&s| s != StrategyName::Seq)
        .collect();
    let bests: Vec<(StrategyName, Vec<Best>)> = strategies
        .iter()
        .map(|&s| (s, series::best_per_cores(rows, g, s)))
        .collect();
    // A contended reference makes every speedup doubtful: none enters a finding then.
    let seq_trusted = !rows
        .iter()
        .any(|r| r.group() == *g && r.is_reference() && r.contended == Some(true));
    let mut out = Vec::new();
    if !seq_trusted {
        out.push(
            "The seq reference was contended (other work used the machine while it ran): no \
             speedup, serial fraction or comparison with the paper is given as a finding."
                .to_owned(),
        );
    }
    for c in series::cores(rows, g) {
        let at: Vec<(&str, &Best)> = bests
            .iter()
            .filter_map(|(s, b)| Some((s.as_str(), b.iter().find(|b| b.cores == c)?)))
            .collect();
        out.extend(winner(c, &at, seq_trusted));
        if c == 1 && seq_trusted {
            out.extend(one_core_noise(&at));
        }
    }
    out.extend(chunking(rows, g, &strategies));
    if seq_trusted {
        out.extend(karp_flatt(&bests));
        out.extend(against_paper(rows, g, &bests));
    }
    out
}

/// A strategy's best cell at one core count.
type Entry<'a> = (&'a str, &'a Best);

/// What can be said about the fastest strategy at one core count, from the cells measured
/// without contention (fastest first).
#[derive(Debug, Clone, PartialEq)]
enum Verdict<'a> {
    /// Only one cell.
    Only(Entry<'a>),
    /// Several, but some without confidence intervals: the lowest mean only.
    NoIntervals(Entry<'a>),
    /// The fastest cell's interval overlaps no other's.
    Fastest {
        /// The fastest.
        winner: Entry<'a>,
        /// The second fastest.
        runner_up: Entry<'a>,
    },
    /// The fastest cell's interval overlaps these (the fastest first).
    Tied {
        /// The cells whose intervals overlap the fastest one's, and it.
        tied: Vec<Entry<'a>>,
        /// How many are slower beyond the overlap.
        slower: usize,
    },
}

/// The verdict on `trusted` (sorted fastest first); `None` when it is empty.
fn verdict<'a>(trusted: &[Entry<'a>]) -> Option<Verdict<'a>> {
    let &first = trusted.first()?;
    if trusted.len() == 1 {
        return Some(Verdict::Only(first));
    }
    if trusted.iter().any(|(_, b)| b.mean_ci.is_none()) {
        return Some(Verdict::NoIntervals(first));
    }
    let mut tied = vec![first];
    tied.extend(
        trusted[1..]
            .iter()
            .copied()
            .filter(|(_, b)| match (first.1.mean_ci, b.mean_ci) {
                (Some(a), Some(o)) => a.overlaps(&o),
                _ => true,
            }),
    );
    Some(if tied.len() == 1 {
        Verdict::Fastest {
            winner: first,
            runner_up: trusted[1],
        }
    } else {
        let slower = trusted.len() - tied.len();
        Verdict::Tied { tied, slower }
    })
}

/// Who is fastest at `cores`, if anyone can be said to be, as a sentence.
// Over ~60 lines on purpose: one sentence per verdict ([`verdict`] decides; this only words it).
fn winner(cores: usize, at: &[Entry<'_>], seq_trusted: bool) -> Option<String> {
    let contended = at.iter().filter(|(_, b)| b.contended).count();
    let mut trusted: Vec<Entry<'_>> = at.iter().copied().filter(|(_, b)| !b.contended).collect();
    trusted.sort_by(|a, b| a.1.mean_s.total_cmp(&b.1.mean_s));
    let left_out = match contended {
        0 => String::new(),
        1 => " (1 contended cell left out)".to_owned(),
        k => format!(" ({k} contended cells left out)"),
    };
    let where_ = format!(
        "At {}{}",
        series::cores_label(cores),
        if at.iter().any(|(_, b)| b.oversubscribed) {
            " (⚠ oversubscribed: more threads than the machine has)"
        } else {
            ""
        }
    );
    let describe = |(s, b): Entry<'_>| {
        format!(
            "{s}{} ({} s{})",
            b.chunks
                .map_or_else(String::new, |k| format!(" with {k} chunks")),
            secs(b.mean_s),
            interval(b.mean_ci)
        )
    };
    Some(match verdict(&trusted)? {
        Verdict::Only(w) => {
            let only = if contended > 0 {
                "was measured without contention"
            } else {
                "was measured"
            };
            format!("{where_}, only {} {only}{left_out}.", describe(w))
        }
        Verdict::NoIntervals(w) => format!(
            "{where_}, the lowest mean is {}, but these cells have no confidence intervals (one \
             trial, or a sweep older than them), so no strategy can be called fastest{left_out}.",
            describe(w)
        ),
        Verdict::Fastest { winner, runner_up } => {
            let (wb, rb) = (winner.1, runner_up.1);
            // At one core a speedup is the reference's noise (said separately), not a result.
            let speed = wb
                .speedup
                .filter(|_| cores > 1 && seq_trusted)
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
            "{where_}, {} are indistinguishable within the trial spread (their 95 % intervals \
             overlap){}{left_out}.",
            and_list(&tied.into_iter().map(describe).collect::<Vec<_>>()),
            match slower {
                0 => String::new(),
                1 => "; the other strategy is slower".to_owned(),
                _ => "; the others are slower".to_owned(),
            }
        ),
    })
}

/// `a`, `a and b`, `a, b and c`.
fn and_list(items: &[String]) -> String {
    match items {
        [] => String::new(),
        [one] => one.clone(),
        [init @ .., last] => format!("{} and {last}", init.join(", ")),
    }
}

/// A speedup above 1 at one core is the reference's noise.
fn one_core_noise(at: &[(&str, &Best)]) -> Vec<String> {
    at.iter()
        .filter(|(_, b)| !b.contended)
        .filter_map(|(s, b)| {
            let sp = b.speedup.filter(|&sp| sp > 1.0)?;
            Some(format!(
                "{s}'s speedup of {}{} at 1 core is noise in the seq reference, not a win: one \
                 worker runs the same passes as seq.",
                times(sp),
                interval(b.speedup_ci)
            ))
        })
        .collect()
}

/// Where more chunks stop paying, per chunked strategy.
fn chunking(rows: &[SummaryRow], g: &Group, strategies: &[StrategyName]) -> Vec<String> {
    let mut out = Vec::new();
    for &s in strategies
        .iter()
        .filter(|&&s| series::is_chunked(rows, g, s))
    {
        let parts: Vec<String> = series::chunk_table(rows, g, s)
            .iter()
            .filter(|(_, v)| v.len() > 1)
            .filter_map(|(c, v)| {
                let k = series::chunking_stops_paying(v)?;
                Some(format!("{k} chunks at {}", series::cores_label(*c)))
            })
            .collect();
        if !parts.is_empty() {
            out.push(format!(
                "{s}: more chunks stop paying (no larger chunk count is faster by more than the \
                 trial spread) from {}.",
                parts.join(", ")
            ));
        }
    }
    out
}

/// The serial fraction of the fastest trusted cell at the most cores not oversubscribed,
/// where it means something.
fn karp_flatt(bests: &[(StrategyName, Vec<Best>)]) -> Option<String> {
    let (s, b) = bests
        .iter()
        .flat_map(|(s, b)| b.iter().map(move |b| (s.as_str(), b)))
        .filter(|(_, b)| b.cores > 1 && !b.oversubscribed && !b.contended)
        .filter(|(_, b)| b.speedup.is_some_and(|sp| sp > 1.0))
        .max_by(|a, b| {
            a.1.cores
                .cmp(&b.1.cores)
                .then(b.1.mean_s.total_cmp(&a.1.mean_s))
        })?;
    let e = b.serial_fraction()?;
    Some(format!(
        "Karp–Flatt serial fraction of {s} at {} ({}{}): e = {}. It describes the runs \
         measured here; from so few core counts it forecasts nothing about more cores.",
        series::cores_label(b.cores),
        times(b.speedup?),
        interval(b.speedup_ci),
        super::numbers::sig(e)
    ))
}

/// The paper's published speedups beside ours, where comparable.
fn against_paper(
    rows: &[SummaryRow],
    g: &Group,
    bests: &[(StrategyName, Vec<Best>)],
) -> Option<String> {
    if !paper::comparable(g) {
        return None;
    }
    let mut parts = Vec::new();
    for c in series::cores(rows, g) {
        let Some(p) = paper::at(c) else { continue };
        let best = bests
            .iter()
            .filter_map(|(s, b)| Some((s.as_str(), b.iter().find(|b| b.cores == c)?)))
            .filter(|(_, b)| !b.contended)
            .filter_map(|(s, b)| Some((s, b.speedup?, b.oversubscribed)))
            .max_by(|a, b| a.1.total_cmp(&b.1));
        if let Some((s, sp, over)) = best {
            parts.push(format!(
                "at {}{} the best here is {} ({s}) against the paper's {}",
                series::cores_label(c),
                if over {
                    " (⚠ oversubscribed here)"
                } else {
                    ""
                },
                times(sp),
                times(p.speedup)
            ));
        }
    }
    (!parts.is_empty()).then(|| {
        format!(
            "Against the paper's published speedups (its machine, its program): {}.",
            parts.join("; ")
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::results::rows::tests::row;

    fn with_ci(mut r: SummaryRow, low: f64, high: f64) -> SummaryRow {
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
        let f = findings(&rows, &rows[0].group());
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
        let f = findings(&rows, &rows[0].group());
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
        let f = findings(&rows, &rows[0].group());
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
        let f = findings(&rows, &rows[0].group()).join("\n");
        assert!(f.contains("at 1 core is noise in the seq reference"), "{f}");
        assert!(f.contains("e = 0.100"), "{f}");
        assert!(!f.contains("no number of cores"), "{f}");
    }

    #[test]
    fn a_contended_reference_gives_no_speedup_finding() {
        let mut seq = row(StrategyName::Seq, 1, None, 4.0);
        seq.contended = Some(true);
        let rows = vec![seq, row(StrategyName::RayonChunks, 2, Some(10), 2.2)];
        let f = findings(&rows, &rows[0].group()).join("\n");
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
        let f = findings(&rows, &rows[0].group()).join("\n");
        assert!(!f.contains("Karp–Flatt"), "{f}");
    }
}
