//! A group's "Where the curves bend" (pure): what a pass costs each strategy at each core
//! count (`sweep --pass-cost`) set against the work this workload's pass gives each thread,
//! the speedup those two allow, the speedup measured, and the OpenMP anchor's
//! (`sweep --anchor`) beside them.
//!
//! The model is the simplest that explains a bend: a step is `P` passes (the preset's), `seq`
//! takes `S` a step, so a pass holds `S / P` of work and, shared by `p` threads, `W = S / (P p)`
//! a thread. A strategy that costs `c` a pass beyond its work then takes `W + c` a pass where
//! `seq` takes `p W`: were that its only loss, its speedup would be `p W / (W + c)`. It is a
//! model, not a bound: it leaves out what else bends a curve (a step's serial parts, uneven
//! chunks, memory bandwidth, a shared core), so a measured speedup well under it says the cost
//! is elsewhere; and `c` is measured apart, with a few µs of work a thread and one chunk a
//! thread, so a run's passes may cost more (many chunks) or less (a quieter spell) than `c`,
//! and a measured speedup well above it says so.

use std::fmt::Write as _;

use super::cell::Best;
use super::load::Sweep;
use super::numbers::{interval, sig, times};
use super::table::{Column, Table};
use super::view::GroupView;
use sph_harness::results::anchor::{AnchorRun, same_state, speedups};
use sph_harness::results::stats::median;
use sph_harness::run::pass_cost::CostRow;
use sph_harness::topology::Pin;
use sph_solver::solver::Pass;

/// Efficiency the model must fall under for a strategy's curve to count as bent: its pass
/// cost is then more than a quarter of the work a thread.
pub const BENT: f64 = 0.8;

/// Writes the section for `v` from the sweeps that hold it; nothing when they measured neither
/// pass costs nor the anchor.
pub fn section(md: &mut String, v: &GroupView, sweeps: &[&Sweep]) {
    let costs: Vec<&CostRow> = sweeps.iter().flat_map(|s| &s.pass_costs).collect();
    let anchor: Vec<AnchorRun> = sweeps
        .iter()
        .flat_map(|s| s.anchor.iter().cloned())
        .filter(|r| r.n == v.group.n && r.steps == v.group.steps)
        .collect();
    let applies = sph_harness::sweep::anchor::applies(&v.group);
    let with_anchor = applies && !anchor.is_empty();
    if costs.is_empty() && !with_anchor {
        return;
    }
    let _ = writeln!(md, "### Where the curves bend\n");
    let Some(seq) = v
        .rows
        .iter()
        .find(|r| r.is_reference() && r.is_usable())
        .and_then(|r| Some((r.mean_s?, r.checksum.as_str())))
    else {
        let _ = writeln!(
            md,
            "No usable `seq` cell: nothing to set the costs against.\n"
        );
        return;
    };
    let passes = if v.group.preset.is_mueller() {
        Pass::MUELLER.len()
    } else {
        Pass::WCSPH.len()
    };
    let pass_us = seq.0 / (v.group.steps * passes) as f64 * 1e6;
    let _ = writeln!(
        md,
        "A step of this workload is {passes} passes; `seq` takes {} µs a step, so a pass holds \
         {} µs of work, W = {} µs / p a thread at p threads. A strategy whose pass costs c \
         beyond its work (measured apart by `--pass-cost`: 5 µs of work a thread, one chunk a \
         thread) would reach p·W / (W + c) were that its only loss; it bends where c nears W. \
         The model leaves out the step's serial parts, uneven chunks, memory bandwidth and a \
         shared core, and c moves with the machine's state.\n",
        sig(pass_us * passes as f64),
        sig(pass_us),
        sig(pass_us)
    );
    let bests: Vec<Best> = v
        .series_bests()
        .into_iter()
        .filter(|(k, _)| k.pin == Pin::None)
        .flat_map(|(_, b)| b)
        .collect();
    let mut table = Table::new([
        Column::left("strategy"),
        Column::right("cores"),
        Column::right("pass cost c, µs [95 %]"),
        Column::right("work a thread W, µs"),
        Column::right("model p·W/(W+c)"),
        Column::right("measured speedup [95 %]"),
    ]);
    let mut bends = Vec::new();
    for s in v.parallel_strategies() {
        let name = s.info().name;
        let mut rows: Vec<&&CostRow> = costs
            .iter()
            .filter(|c| c.strategy == name && c.cores >= 2)
            .collect();
        rows.sort_by_key(|c| c.cores);
        for c in &rows {
            let (w, expected) = model(c, pass_us);
            let measured = bests
                .iter()
                .find(|b| b.strategy == s && b.cores == c.cores)
                .and_then(|b| {
                    let chunks = b.chunks.map_or(String::new(), |k| format!(" ({k} chunks)"));
                    Some(format!(
                        "{}{}{chunks}",
                        times(b.speedup?),
                        interval(b.speedup_ci)
                    ))
                })
                .unwrap_or_else(|| "–".into());
            let flag = if c.oversubscribed {
                " ⚠ oversubscribed"
            } else {
                ""
            };
            table.row([
                name.to_string(),
                c.cores.to_string(),
                format!(
                    "{} [{}–{}]",
                    sig(c.beyond_work_us),
                    sig(c.pass_low_us - c.work_us),
                    sig(c.pass_high_us - c.work_us)
                ),
                sig(w),
                format!("{}{flag}", times(expected)),
                measured,
            ]);
        }
        let apart = rows.iter().find_map(|c| {
            let (_, model) = model(c, pass_us);
            let b = bests
                .iter()
                .find(|b| b.strategy == s && b.cores == c.cores)?;
            let (interval, speedup) = (b.speedup_ci?, b.speedup?);
            (interval.high < model || interval.low > model).then_some(Apart {
                cores: c.cores,
                speedup,
                model,
            })
        });
        bends.push(bend_sentence(name, &rows, pass_us, apart));
    }
    let anchor_note = anchor_rows(&mut table, &anchor, v, seq, applies);
    let _ = writeln!(md, "{table}");
    for b in bends.iter().flatten() {
        let _ = writeln!(md, "- {b}");
    }
    if !bends.iter().all(Option::is_none) {
        md.push('\n');
    }
    if let Some(note) = anchor_note {
        let _ = writeln!(md, "{note}\n");
    }
}

/// The work a thread of a pass of `pass_us` at `c.cores` threads, W, and the speedup the
/// model gives a pass cost of `c`, p·W / (W + c).
fn model(c: &CostRow, pass_us: f64) -> (f64, f64) {
    let w = pass_us / c.cores as f64;
    (w, c.cores as f64 * w / (w + c.beyond_work_us.max(0.0)))
}

/// A core count where the measured speedup's whole interval lies off the model.
struct Apart {
    cores: usize,
    speedup: f64,
    model: f64,
}

/// Where `name`'s model first falls under [`BENT`] efficiency, as a sentence, and where its
/// measured speedup's interval lies off the model (`apart`), what that says; `None` without
/// pass costs.
fn bend_sentence(
    name: &str,
    rows: &[&&CostRow],
    pass_us: f64,
    apart: Option<Apart>,
) -> Option<String> {
    let last = rows.last()?;
    let bent = rows
        .iter()
        .find(|c| model(c, pass_us).1 / (c.cores as f64) < BENT);
    let mut text = match bent {
        Some(c) => format!(
            "**{name}** bends at {} cores: its pass costs {} µs there, more than a quarter of \
             the {} µs of work a thread, so the model stays under {:.0} % efficiency even with \
             nothing else lost.",
            c.cores,
            sig(c.beyond_work_us),
            sig(pass_us / c.cores as f64),
            BENT * 100.0
        ),
        None => format!(
            "**{name}**: its pass cost stays under a quarter of the work a thread up to {} \
             cores: the cost of a pass does not bend its curve here.",
            last.cores
        ),
    };
    if let Some(Apart {
        cores,
        speedup,
        model,
    }) = apart
    {
        let why = if speedup < model {
            "under its model's {model} (the whole interval): what holds it back there is not a \
             pass's fork and join but something the model leaves out (more tasks or chunks than \
             threads, uneven chunks, the step's serial parts, a shared core)"
        } else {
            "above its model's {model} (the whole interval): its passes cost it less in these \
             runs than the pass-cost measurement, made apart, says"
        };
        let _ = write!(
            text,
            " At {cores} cores it measured {}, {}.",
            times(speedup),
            why.replace("{model}", &times(model))
        );
    }
    Some(text)
}

/// Adds the anchor's speedups to `table` where they compare (the group is the plain loop's
/// and every run computed `seq`'s state; `seq` is its mean seconds and checksum), and
/// returns what to say of it.
fn anchor_rows(
    table: &mut Table,
    anchor: &[AnchorRun],
    v: &GroupView,
    (seq_s, checksum): (f64, &str),
    applies: bool,
) -> Option<String> {
    if anchor.is_empty() || !applies {
        return None;
    }
    let (n, steps) = (v.group.n, v.group.steps);
    if !same_state(anchor, n, steps, checksum) {
        return Some(
            "⚠ The OpenMP anchor's runs ended in another state than `seq`'s (another \
             checksum): it did not compute this workload, so its speedups are not shown."
                .into(),
        );
    }
    for s in speedups(anchor, n, steps) {
        let flag = if anchor
            .iter()
            .any(|r| r.threads == s.threads && r.oversubscribed)
        {
            " ⚠ oversubscribed"
        } else {
            ""
        };
        table.row([
            "OpenMP plain loop".to_string(),
            s.threads.to_string(),
            "–".into(),
            "–".into(),
            "–".into(),
            format!(
                "{}{}{flag}",
                times(s.speedup.value),
                interval(s.speedup.interval)
            ),
        ]);
    }
    let one: Vec<f64> = anchor
        .iter()
        .filter(|r| r.threads == 1)
        .map(|r| r.wall_s)
        .collect();
    let pace = (!one.is_empty())
        .then(|| median(&one))
        .map_or(String::new(), |median| {
            format!(
                " On one thread it takes {} s a run (median), {} `seq`'s {} s: each of its passes \
             holds that much more work, so the same fork and join costs it that much less of \
             a pass — compare speedups knowing that, and times for what each run costs.",
                sig(median),
                times(median / seq_s),
                sig(seq_s)
            )
        });
    Some(format!(
        "The OpenMP plain loop is `benches/plain-loop/mueller.cpp` built with `-fopenmp` \
         (each pass `omp parallel for schedule(static)`), run by the sweep after its cells on \
         the same machine, in rounds; its speedup pairs each round's run with the round's \
         1-thread run, and it computed `seq`'s state bit for bit. It ran after the cells, so \
         it stands beside them, not paired with them: no finding compares the two.{pace}"
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::report::view::tests::view;
    use sph_harness::results::fixtures::sweep_on;
    use sph_strategies::StrategyName::{RayonChunks, Seq};

    const NONE: Pin = Pin::None;

    /// The tests' group (N = 60, 3 steps of Müller's 2 passes) with `seq` at 6 ms a run: a
    /// pass holds 1000 µs of work, 500 µs a thread at 2 threads; rayon-chunks at 2 cores takes
    /// 4 ms.
    fn group_and_sweep(cost_us: f64, anchor: Vec<AnchorRun>) -> (GroupView, Sweep) {
        let v = view(&[
            (Seq, 1, None, NONE, &[0.006, 0.006, 0.006]),
            (RayonChunks, 2, Some(10), NONE, &[0.004, 0.004, 0.004]),
        ]);
        let mut s = sweep_on("results/a", "cpu", 2, v.rows.clone());
        s.pass_costs = vec![CostRow {
            strategy: "rayon-chunks".into(),
            cores: 2,
            work_us: 5.0,
            pass_us: 5.0 + cost_us,
            pass_low_us: 4.9 + cost_us,
            pass_high_us: 5.1 + cost_us,
            beyond_work_us: cost_us,
            oversubscribed: false,
        }];
        s.anchor = anchor;
        (v, s)
    }

    fn anchor_run(threads: usize, round: usize, wall_s: f64, checksum: &str) -> AnchorRun {
        AnchorRun {
            n: 60,
            steps: 3,
            seed: 1,
            threads,
            round,
            position: 1,
            wall_s,
            checksum: checksum.into(),
            oversubscribed: false,
        }
    }

    fn render(v: &GroupView, s: &Sweep) -> String {
        let mut md = String::new();
        section(&mut md, v, &[s]);
        md
    }

    #[test]
    fn the_model_is_the_work_a_thread_over_work_and_cost() {
        // W = 500 µs, c = 100 µs: 2 · 500 / 600 = 1.67×.
        let (v, s) = group_and_sweep(100.0, Vec::new());
        let md = render(&v, &s);
        assert!(
            md.contains("`seq` takes 2000 µs a step, so a pass holds 1000 µs"),
            "{md}"
        );
        assert!(
            md.contains("| rayon-chunks | 2 | 100 [99.9–100] | 500 | 1.67× | 1.50×"),
            "{md}"
        );
        assert!(md.contains("(10 chunks)"), "{md}");
        assert!(
            md.contains("**rayon-chunks**: its pass cost stays under a quarter"),
            "{md}"
        );
    }

    #[test]
    fn a_pass_cost_over_a_quarter_of_the_work_a_thread_bends_the_curve() {
        // c = 200 µs > 500 / 4: efficiency 500 / 700 < 0.8.
        let (v, s) = group_and_sweep(200.0, Vec::new());
        let md = render(&v, &s);
        assert!(md.contains("**rayon-chunks** bends at 2 cores"), "{md}");
        assert!(md.contains("under 80 % efficiency"), "{md}");
    }

    #[test]
    fn a_measured_speedup_off_its_model_says_where_the_model_misses() {
        // Model 2 · 500 / 510 = 1.96×; measured 1.5× with an interval of width 0 (equal
        // rounds): under the model.
        let (v, s) = group_and_sweep(10.0, Vec::new());
        let md = render(&v, &s);
        assert!(
            md.contains("At 2 cores it measured 1.50×, under its model's 1.96×"),
            "{md}"
        );
        // c = 1000 µs: model 2 · 500 / 1500 = 0.667×, under the measured 1.5×: said too.
        let (v, s) = group_and_sweep(1000.0, Vec::new());
        let md = render(&v, &s);
        assert!(!md.contains("under its model"), "{md}");
        assert!(
            md.contains("At 2 cores it measured 1.50×, above its model's 0.667×"),
            "{md}"
        );
    }

    #[test]
    fn the_anchor_shows_only_where_it_computed_seqs_state() {
        let checksum = v_checksum();
        let runs = |sum: &str| {
            (1..=3)
                .flat_map(|r| [anchor_run(1, r, 1.0, sum), anchor_run(2, r, 0.5, sum)])
                .collect::<Vec<_>>()
        };
        let (v, s) = group_and_sweep(10.0, runs(&checksum));
        let md = render(&v, &s);
        assert!(
            md.contains("| OpenMP plain loop | 2 | – | – | – | 2.00×"),
            "{md}"
        );
        let (v, s) = group_and_sweep(10.0, runs("0000000000000000"));
        let md = render(&v, &s);
        assert!(!md.contains("| OpenMP plain loop |"), "{md}");
        assert!(md.contains("did not compute this workload"), "{md}");
    }

    #[test]
    fn without_pass_costs_or_anchor_there_is_no_section() {
        let (v, mut s) = group_and_sweep(10.0, Vec::new());
        s.pass_costs.clear();
        assert_eq!(render(&v, &s), "");
    }

    fn v_checksum() -> String {
        let (v, _) = group_and_sweep(0.0, Vec::new());
        v.rows[0].checksum.clone()
    }
}
