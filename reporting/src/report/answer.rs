//! The answer first: right under REPORT.md's build line (and the banners that qualify every
//! number: test data, partial study, contended cells, rows left out, unchecked statistics),
//! per group and core count, which strategy is fastest (at which chunks), its paired speedup
//! over `seq`, and whether its paired rounds resolve it against the runner-up — or, where the
//! group's findings are withheld, why.
//!
//! Nothing here is decided anew: [`answer`] reads the group's own findings
//! ([`super::findings::findings`], computed once per group and shared with the group's
//! section), its verdict per core count ([`Verdict`]) and its withheld reasons; [`markdown`]
//! words them as one table. Where the table would pass [`MAX_ROWS`] rows, each group shows its
//! highest core counts and the rest are left to its section's findings.

use std::fmt::Write as _;

use super::cell::Best;
use super::findings::{AtCores, Finding, Withheld};
use super::numbers::{faster, plus_minus};
use super::table::{Column, Table};
use super::verdict::{Entry, Verdict, and_list};
use super::view::{Design, GroupView};
use sph_harness::results::intervals::MIN_ROUNDS;
use sph_harness::results::key::LabelStyle;

/// The heading of the section.
pub const HEADING: &str = "## The answer";

/// The most rows the table holds; past it each group shows only its highest core counts.
pub const MAX_ROWS: usize = 20;

/// What a group's findings say at one core count, or why they say nothing.
#[derive(Debug, Clone, PartialEq)]
pub enum Said {
    /// The group's findings are withheld, and why (one row for the group).
    Withheld(Withheld),
    /// The group has no usable cell of a parallel strategy (one row for the group).
    Nothing,
    /// The verdict at one core count, and whether the group's `seq` reference is trusted
    /// (uncontended), so that speedups may be stated.
    At {
        /// The finding at that core count.
        at: AtCores,
        /// The `seq` reference was measured without contention.
        seq_trusted: bool,
    },
    /// At this core count every strategy's best cell was contended: none enters a finding.
    AllContended(usize),
}

/// The answer of one group.
#[derive(Debug, Clone, PartialEq)]
pub struct GroupAnswer {
    /// The group's label, as its section's heading.
    pub label: String,
    /// Whether its best cells were measured again in confirmation rounds.
    pub confirmed: bool,
    /// Per core count measured, lowest first (or one reason for the whole group).
    pub said: Vec<Said>,
}

/// The answer of each group of `views`, from `found`, their findings (one list per view, in
/// the same order).
pub fn answer(views: &[GroupView], found: &[Vec<Finding>]) -> Vec<GroupAnswer> {
    views
        .iter()
        .zip(found)
        .map(|(v, found)| GroupAnswer {
            label: v.group.label(LabelStyle::Report),
            confirmed: v.is_confirmed(),
            said: said(v, found),
        })
        .collect()
}

/// What `found`, the findings of `v`, say per core count.
fn said(v: &GroupView, found: &[Finding]) -> Vec<Said> {
    if let Some(why) = found.iter().find_map(|f| match f {
        Finding::Withheld(why) => Some(*why),
        _ => None,
    }) {
        return vec![Said::Withheld(why)];
    }
    let seq_trusted = !found.contains(&Finding::ContendedReference);
    let mut out = Vec::new();
    for c in v.cores() {
        let at = found.iter().find_map(|f| match f {
            Finding::AtCores(at) if at.cores == c => Some(at.clone()),
            _ => None,
        });
        match at {
            Some(at) => out.push(Said::At { at, seq_trusted }),
            // No verdict though cells were measured: every best cell there was contended.
            None if v.rows.iter().any(|r| {
                r.cores == c && !r.is_reference() && r.is_usable() && r.contended == Some(true)
            }) =>
            {
                out.push(Said::AllContended(c));
            }
            None => {}
        }
    }
    if out.is_empty() {
        out.push(Said::Nothing);
    }
    out
}

/// The section: its heading, what the columns mean, the table, and which core counts it
/// leaves to the groups' sections.
pub fn markdown(groups: &[GroupAnswer]) -> String {
    let mut md = format!("{HEADING}\n\n");
    if groups.is_empty() {
        md.push_str("No group was measured.\n\n");
        return md;
    }
    md.push_str(
        "Per workload and core count, from the findings in its section below: the strategy \
         whose best cell has the lowest mean time (at its best chunks), its paired speedup over \
         `seq`, and that cell against the next lowest mean, paired by round. **Bold**: \
         fastest, its 95 % interval excluding 1 against every other strategy; *not resolved*: \
         the paired rounds do not separate it from the strategies named. Where even the \
         fastest strategy did not beat `seq` (its speedup's interval holds 1, or lies below \
         it), the speedup says so.\n\n",
    );
    let mut t = Table::new([
        Column::left("workload"),
        Column::right("cores"),
        Column::left("fastest"),
        Column::right("speedup (95 % CI)"),
        Column::left("vs runner-up"),
    ]);
    let rows: usize = groups.iter().map(|g| g.said.len()).sum();
    let shown = if rows > MAX_ROWS {
        (MAX_ROWS / groups.len()).max(1)
    } else {
        usize::MAX
    };
    let mut left: Vec<(&str, String)> = Vec::new();
    for g in groups {
        let from = g.said.len().saturating_sub(shown);
        let label = if g.confirmed || !g.said.iter().any(|s| matches!(s, Said::At { .. })) {
            g.label.clone()
        } else {
            format!("{} ⚠ not confirmed", g.label)
        };
        for s in &g.said[from..] {
            t.row(std::iter::once(label.clone()).chain(cells(s)));
        }
        if from > 0 {
            let hidden: Vec<String> = g.said[..from].iter().map(cores_of).collect();
            left.push((&g.label, and_list(&hidden)));
        }
    }
    let _ = writeln!(md, "{t}");
    if let Some((_, first)) = left.first() {
        let others = if left.iter().all(|(_, c)| c == first) {
            format!("{first} cores")
        } else {
            left.iter()
                .map(|(g, c)| format!("{g}: {c} cores"))
                .collect::<Vec<_>>()
                .join("; ")
        };
        let _ = writeln!(
            md,
            "Each group's {shown} highest core counts are shown; the others ({others}) are in \
             its section's findings.\n"
        );
    }
    md
}

/// The core count of a row (`—` for a whole group's).
fn cores_of(s: &Said) -> String {
    match s {
        Said::At { at, .. } => at.cores.to_string(),
        Said::AllContended(c) => c.to_string(),
        Said::Withheld(_) | Said::Nothing => "—".to_owned(),
    }
}

/// A row's cells after the workload: cores, fastest, speedup, against the runner-up.
fn cells(s: &Said) -> [String; 4] {
    // A row without a fastest cell: its cores (or a dash), dashes, and why.
    let none = |cores: String, why: &str| [cores, "—".into(), "—".into(), format!("— {why}")];
    let (at, seq_trusted) = match s {
        Said::Withheld(why) => return none("—".into(), &reason(*why)),
        Said::Nothing => return none("—".into(), "no parallel strategy has a usable cell"),
        Said::AllContended(c) => {
            return none(c.to_string(), "every cell contended, none enters a finding");
        }
        Said::At { at, seq_trusted } => (at, *seq_trusted),
    };
    let speedup = |(_, b): &Entry| match b.speedup {
        _ if !seq_trusted => "— (seq contended)".to_owned(),
        Some(s) => format!("{}{}", plus_minus(s, b.speedup_ci), against_seq(b)),
        None => "—".to_owned(),
    };
    let left_out = match at.contended {
        0 => String::new(),
        1 => "; 1 contended cell left out".to_owned(),
        k => format!("; {k} contended cells left out"),
    };
    let (winner, first, against) = match &at.verdict {
        Verdict::Fastest {
            winner,
            runner_up,
            by,
        } => (
            winner,
            format!("**{}**", cell(&winner.1)),
            faster(by, &cell(&runner_up.1)),
        ),
        Verdict::Tied { tied, .. } => {
            let others: Vec<String> = tied[1..].iter().map(|(_, b)| b.key().to_string()).collect();
            (
                &tied[0],
                cell(&tied[0].1),
                format!("*not resolved* against {}", and_list(&others)),
            )
        }
        Verdict::Only(w) => (w, cell(&w.1), "the only strategy measured".to_owned()),
        Verdict::Unknown { lowest: w, why, .. } => {
            (w, cell(&w.1), format!("no order: {}", why.phrase()))
        }
    };
    let flag = if at.oversubscribed {
        " ⚠ oversubscribed"
    } else {
        ""
    };
    [
        format!("{}{flag}", at.cores),
        first,
        speedup(winner),
        format!("{against}{left_out}"),
    ]
}

/// What the fastest cell's speedup interval says against `seq` where it did not beat it:
/// below 1, slower; holding 1 on more than one core, not distinguishable (on one core every
/// strategy does `seq`'s work, so a tie there is the expected result and goes unsaid).
fn against_seq(b: &Best) -> &'static str {
    match b.speedup_ci {
        Some(i) if i.high < 1.0 => ", slower than `seq`",
        Some(i) if i.low <= 1.0 && b.cores > 1 => ", not distinguishable from `seq`",
        _ => "",
    }
}

/// A best cell by its series and chunks: `crossbeam-pool, 10 chunks`.
fn cell(b: &Best) -> String {
    match b.chunks {
        Some(k) => format!("{}, {k} chunks", b.key()),
        None => b.key().to_string(),
    }
}

/// Why a group's findings are withheld, in a few words.
fn reason(why: Withheld) -> String {
    match why {
        Withheld::Unchecked => {
            "findings withheld: no trials.csv, so its statistics were not checked".to_owned()
        }
        Withheld::Design(Design::BeforeRounds) => {
            "findings withheld: an older sweep, measured before rounds".to_owned()
        }
        Withheld::Design(_) => {
            "findings withheld: measured cell after cell (`--schedule cells`)".to_owned()
        }
        Withheld::Rounds(k) => format!(
            "no finding: {}, an interval needs {MIN_ROUNDS}",
            sph_harness::output::console::plural(k, "round", "rounds")
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::report::findings::findings;
    use crate::report::findings::tests::SEQ;
    use crate::report::view::tests::{Spec, measured, view, with_trials};
    use sph_harness::results::rows::Phase;
    use sph_harness::topology::Pin;
    use sph_strategies::StrategyName::{CrossbeamPool, RayonChunks, RayonIter, Seq};

    const NONE: Pin = Pin::None;

    /// The answer of the groups `views`, from their own findings, and its markdown.
    fn answered(views: &[GroupView]) -> (Vec<GroupAnswer>, String) {
        let found: Vec<Vec<Finding>> = views.iter().map(findings).collect();
        let a = answer(views, &found);
        let md = markdown(&a);
        (a, md)
    }

    /// The table's rows.
    fn rows(md: &str) -> Vec<&str> {
        md.lines()
            .filter(|l| l.starts_with("| ") && !l.starts_with("| workload"))
            .collect()
    }

    /// The verdicts of the group's findings, by cores.
    fn verdicts(v: &GroupView) -> Vec<(usize, Verdict)> {
        findings(v)
            .into_iter()
            .filter_map(|f| match f {
                Finding::AtCores(at) => Some((at.cores, at.verdict)),
                _ => None,
            })
            .collect()
    }

    /// Rounds that drift alike (×1, ×1.2, ×0.8): rayon-iter 5 % slower than rayon-chunks in
    /// every round at 2 cores.
    const RESOLVED: [Spec<'static>; 5] = [
        (Seq, 1, None, NONE, &SEQ),
        (RayonChunks, 1, Some(10), NONE, &[4.0, 4.9, 3.1]),
        (RayonIter, 1, None, NONE, &[3.9, 4.9, 3.1]),
        (RayonChunks, 2, Some(10), NONE, &[2.0, 2.4, 1.6]),
        (RayonIter, 2, None, NONE, &[2.1, 2.52, 1.68]),
    ];

    #[test]
    fn the_fastest_is_the_findings_winner_in_bold_with_its_speedup_and_margin() {
        let v = view(&RESOLVED);
        let (a, md) = answered(std::slice::from_ref(&v));
        let rows = rows(&md);
        assert_eq!(rows.len(), 2, "{md}");
        // At 2 cores the findings resolve rayon-chunks against rayon-iter...
        let at_two = &verdicts(&v)[1];
        let Verdict::Fastest { winner, by, .. } = &at_two.1 else {
            panic!("{at_two:?}");
        };
        assert_eq!(
            (at_two.0, winner.0, winner.1.chunks),
            (2, RayonChunks, Some(10))
        );
        // ...and the answer names it, as they do.
        assert_eq!(
            rows[1],
            format!(
                "| {} ⚠ not confirmed | 2 | **rayon-chunks, 10 chunks** | 2.00 ± 0.00× | {} |",
                v.group.label(LabelStyle::Report),
                faster(by, "rayon-iter")
            ),
            "{md}"
        );
        assert!(
            rows[1].ends_with("| 1.05 ± 0.00× faster than rayon-iter |"),
            "{md}"
        );
        // At 1 core the rounds disagree: the lowest mean, not in bold, not resolved.
        assert!(
            rows[0].contains("| 1 | rayon-iter | ")
                && rows[0].ends_with("| *not resolved* against rayon-chunks |"),
            "{md}"
        );
        assert!(matches!(verdicts(&v)[0].1, Verdict::Tied { .. }));
        assert!(matches!(
            &a[0].said[1],
            Said::At {
                seq_trusted: true,
                ..
            }
        ));
    }

    #[test]
    fn a_fastest_strategy_that_does_not_beat_seq_says_so() {
        // rayon-chunks beats rayon-iter in every round at 2 cores, but neither beats seq: the
        // rounds put rayon-chunks at 0.95x, 1.07x and 1.0x of seq's time.
        let v = view(&[
            (Seq, 1, None, NONE, &SEQ),
            (RayonChunks, 2, Some(10), NONE, &[4.2, 4.5, 3.2]),
            (RayonIter, 2, None, NONE, &[4.41, 4.73, 3.36]),
            (CrossbeamPool, 2, Some(10), NONE, &[6.0, 7.2, 4.8]),
        ]);
        let (_, md) = answered(std::slice::from_ref(&v));
        let row = rows(&md)[0];
        assert!(
            row.contains("| 2 | **rayon-chunks, 10 chunks** | ")
                && row.contains("×, not distinguishable from `seq` | "),
            "{md}"
        );
        // Slower than seq in every round: said as slower.
        let v = view(&[
            (Seq, 1, None, NONE, &SEQ),
            (RayonChunks, 2, Some(10), NONE, &[5.0, 6.0, 4.0]),
            (RayonIter, 2, None, NONE, &[5.5, 6.6, 4.4]),
        ]);
        let (_, md) = answered(std::slice::from_ref(&v));
        assert!(
            rows(&md)[0].contains("| 0.800 ± 0.000×, slower than `seq` | "),
            "{md}"
        );
        // Faster than seq: nothing added (the test above has 2.00 ± 0.00× alone).
        let (_, md) = answered(&[view(&RESOLVED)]);
        assert!(!md.contains("than `seq` |"), "{md}");
    }

    #[test]
    fn not_resolved_where_the_findings_do_not_separate_the_cells() {
        // The same means as above, but rounds that disagree.
        let v = view(&[
            (Seq, 1, None, NONE, &SEQ),
            (RayonChunks, 2, Some(10), NONE, &[2.0, 2.4, 1.6]),
            (RayonIter, 2, None, NONE, &[2.3, 2.2, 1.8]),
            (CrossbeamPool, 2, Some(10), NONE, &[3.0, 3.6, 2.4]),
        ]);
        let Verdict::Tied { tied, slower } = &verdicts(&v)[0].1 else {
            panic!("{:?}", verdicts(&v));
        };
        assert_eq!((tied.len(), *slower), (2, 1));
        let (_, md) = answered(std::slice::from_ref(&v));
        let row = rows(&md)[0];
        assert!(
            row.contains("| 2 | rayon-chunks, 10 chunks | ")
                && row.ends_with("| *not resolved* against rayon-iter |")
                && !row.contains("**"),
            "{md}"
        );
    }

    #[test]
    fn a_group_without_trials_is_withheld_with_the_reason() {
        let mut v = view(&RESOLVED);
        v.unchecked = true;
        let (a, md) = answered(&[v.clone()]);
        assert_eq!(a[0].said, [Said::Withheld(Withheld::Unchecked)]);
        assert_eq!(
            rows(&md),
            [format!(
                "| {} | — | — | — | — findings withheld: no trials.csv, so its statistics were \
                 not checked |",
                v.group.label(LabelStyle::Report)
            )]
        );
        v.unchecked = false;
        v.design = Design::BeforeRounds;
        let (_, md) = answered(&[v]);
        assert!(
            md.contains("— findings withheld: an older sweep, measured before rounds |"),
            "{md}"
        );
        // Two rounds: no interval, so no finding, and the answer says so.
        let v = view(&[
            (Seq, 1, None, NONE, &[4.0, 4.4]),
            (RayonChunks, 2, Some(10), NONE, &[2.0, 2.2]),
        ]);
        let (_, md) = answered(&[v]);
        assert!(
            md.contains("| — | — | — | — no finding: 2 rounds, an interval needs 3 |"),
            "{md}"
        );
    }

    #[test]
    fn contended_cells_and_a_contended_reference_are_said() {
        let (mut rows_, trials) = measured(
            &[
                (Seq, 1, None, NONE, &SEQ),
                (RayonChunks, 2, Some(10), NONE, &[2.0, 2.4, 1.6]),
                (RayonIter, 2, None, NONE, &[1.0, 1.2, 0.8]),
                (RayonChunks, 3, Some(10), NONE, &[2.0, 2.4, 1.6]),
            ],
            Phase::Grid,
        );
        rows_[2].contended = Some(true);
        rows_[3].contended = Some(true);
        let (_, md) = answered(&[with_trials(rows_.clone(), trials.clone())]);
        let table = rows(&md);
        assert!(
            table[0].contains("| 2 | rayon-chunks, 10 chunks | 2.00 ± 0.00× | the only strategy measured; 1 contended cell left out |"),
            "{md}"
        );
        assert!(
            table[1].ends_with("| 3 | — | — | — every cell contended, none enters a finding |"),
            "{md}"
        );
        rows_[0].contended = Some(true);
        let (_, md) = answered(&[with_trials(rows_, trials)]);
        assert!(
            rows(&md)[0].contains("| rayon-chunks, 10 chunks | — (seq contended) |"),
            "{md}"
        );
    }

    #[test]
    fn an_oversubscribed_core_count_is_flagged() {
        let v = view(&[
            (Seq, 1, None, NONE, &SEQ),
            (RayonChunks, 3, Some(10), NONE, &[2.0, 2.4, 1.6]),
        ]);
        let (_, md) = answered(&[v]);
        assert!(
            rows(&md)[0].contains("| 3 ⚠ oversubscribed | rayon-chunks, 10 chunks |"),
            "{md}"
        );
    }

    #[test]
    fn a_long_table_keeps_each_groups_highest_core_counts_and_says_where_the_rest_are() {
        let times: Vec<[f64; 3]> = (1..=8)
            .map(|c| {
                let t = 4.0 / c as f64;
                [t, t * 1.2, t * 0.8]
            })
            .collect();
        let specs: Vec<Spec<'_>> = std::iter::once((Seq, 1, None, NONE, &SEQ[..]))
            .chain(
                times
                    .iter()
                    .enumerate()
                    .map(|(i, t)| (RayonIter, i + 1, None, NONE, &t[..])),
            )
            .collect();
        let v = view(&specs);
        let views = vec![v.clone(), v.clone(), v.clone()];
        let (a, md) = answered(&views);
        assert_eq!(a.iter().map(|g| g.said.len()).sum::<usize>(), 24);
        let table = rows(&md);
        // 20 rows at most: each of the 3 groups keeps its 6 highest core counts.
        assert_eq!(table.len(), 18, "{md}");
        assert!(
            table[0].contains("| 3 ⚠ oversubscribed | rayon-iter |"),
            "{md}"
        );
        assert!(
            table[5].contains("| 8 ⚠ oversubscribed | rayon-iter |"),
            "{md}"
        );
        assert!(
            md.contains(
                "Each group's 6 highest core counts are shown; the others (1 and 2 cores) are \
                 in its section's findings."
            ),
            "{md}"
        );
    }
}
