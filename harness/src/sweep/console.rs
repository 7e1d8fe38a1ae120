//! What a sweep prints: pure functions from plan and rows to text.

use std::collections::HashMap;
use std::fmt::Write as _;
use std::time::Duration;

use super::plan::{self, Cell, LabelStyle, Plan};
use super::range::{Axis, compact};
use crate::output::console::plural;
use crate::results::params::SweepParams;
use crate::results::rows::{Contended, Phase, Status, SummaryRow, fastest};
use crate::topology::Pin;
use sph_solver::models::Preset;
use sph_solver::models::wcsph;
use sph_solver::scene::Scene;
use sph_strategies::StrategyName;

/// A duration for people: `0.25 ms`, `12 ms`, `4.2 s`, `42 s`, `3 min 20 s`, `1 h 05 min`.
pub fn duration(seconds: f64) -> String {
    if !seconds.is_finite() {
        return "unknown".to_owned();
    }
    // Nothing (an estimate with nothing left to run: an empty float sum is -0.0) or a
    // negative rounding error reads as nothing, never as "-0.00 ms".
    if seconds <= 0.0 {
        return "0 ms".to_owned();
    }
    if seconds < 0.001 {
        return format!("{:.2} ms", seconds * 1000.0);
    }
    if seconds < 1.0 {
        return format!("{:.0} ms", seconds * 1000.0);
    }
    if seconds < 10.0 {
        return format!("{seconds:.1} s");
    }
    let s = seconds.round() as u64;
    match (s / 3600, (s % 3600) / 60, s % 60) {
        (0, 0, sec) => format!("{sec} s"),
        (0, min, sec) => format!("{min} min {sec:02} s"),
        (h, min, _) => format!("{h} h {min:02} min"),
    }
}

/// Decimal places that show `seconds` to four significant digits (at least 1, at most 9).
pub fn places(seconds: f64) -> usize {
    if !(seconds.is_finite() && seconds > 0.0) {
        return 4;
    }
    (3 - seconds.log10().floor() as i64).clamp(1, 9) as usize
}

/// The cells of `plan` with more cores than `hardware_threads`, and their cores values.
pub fn oversubscribed(plan: &Plan, hardware_threads: usize) -> (usize, Vec<usize>) {
    let cells: Vec<&Cell> = plan
        .cells
        .iter()
        .filter(|c| c.oversubscribed(hardware_threads))
        .collect();
    let mut cores: Vec<usize> = cells.iter().map(|c| c.cores).collect();
    cores.sort_unstable();
    cores.dedup();
    (cells.len(), cores)
}

/// What the plan's cores mean on this machine's topology, and the placements measured:
/// `None` when there is nothing to say (no SMT sibling used, placement by the OS only).
pub fn placement_note(
    params: &SweepParams,
    topology: &crate::topology::Topology,
) -> Option<String> {
    use crate::topology::Pin;
    let mut lines = Vec::new();
    if params.pin != [Pin::None] {
        let names: Vec<&str> = params.pin.iter().map(|p| p.as_str()).collect();
        lines.push(format!(
            "  placements: {} (each a cell; seq, the reference, runs unpinned)",
            names.join(", ")
        ));
    }
    let widest = params.cores.iter().copied().max().unwrap_or(1);
    let smt: Vec<String> = params
        .cores
        .iter()
        .filter(|&&c| topology.is_smt(c) == Some(true))
        .map(|c| c.to_string())
        .collect();
    if let (Some(physical), Some(split)) = (topology.physical_cores, topology.split(widest))
        && split.siblings > 0
        && !smt.is_empty()
    {
        lines.push(format!(
            "  this machine has {physical} physical cores and {} hardware threads: cores {} use \
             SMT siblings (smt=true in summary.csv); at {widest} cores, spread puts {} threads on \
             physical cores and {} on siblings",
            topology.logical_cpus,
            smt.join(", "),
            split.physical,
            split.siblings
        ));
    }
    (!lines.is_empty()).then(|| lines.join("\n"))
}

/// The warning printed when some cells ask for more threads than the machine has.
pub fn oversubscription_warning(plan: &Plan, hardware_threads: usize) -> Option<String> {
    let (count, cores) = oversubscribed(plan, hardware_threads);
    (count > 0).then(|| {
        format!(
            "warning: cores {} exceed this machine's {} hardware threads: {} run anyway \
             and are marked oversubscribed=true in summary.csv",
            compact(&cores, Axis::Cores),
            hardware_threads,
            plural(count, "cell", "cells"),
        )
    })
}

/// The note printed when a `wcsph` group runs at a particle count other than its `--n`:
/// which resolution each such `--n` maps to.
pub fn resolution_note(params: &SweepParams) -> Option<String> {
    if !params.presets.contains(&Preset::Wcsph) {
        return None;
    }
    let mapped: Vec<String> = params
        .n
        .iter()
        .filter(|&&n| Scene::dam_break_fluid(Preset::Wcsph, n) != n)
        .map(|&n| {
            let r = wcsph::scene::resolution_for(n);
            format!(
                "--n {n} → R = {r} ({} fluid particles)",
                wcsph::scene::dam_break_particles(r)
            )
        })
        .collect();
    (!mapped.is_empty()).then(|| {
        format!(
            "note: wcsph runs at the resolution R whose 2R² fluid particles are nearest --n: {}",
            mapped.join(", ")
        )
    })
}

/// The lines of a finished phase: a heading naming the group and the phase, then one line
/// per cell in plan order.
pub fn phase_lines(
    plan: &Plan,
    group: &plan::Group,
    phase: Phase,
    rounds: usize,
    rows: &[SummaryRow],
) -> String {
    let what = match phase {
        Phase::Grid => "every cell",
        Phase::Confirm => "the cells the grid chose, measured again",
    };
    let mut text = format!(
        "{} — {} ({}, {}):",
        group.label(LabelStyle::Sweep),
        phase.as_str(),
        what,
        plural(rounds, "round", "rounds")
    );
    let total = plan.cells.len();
    for (at, cell) in plan.cells.iter().enumerate() {
        if let Some(row) = rows.iter().find(|r| r.key() == *cell) {
            let _ = write!(text, "\n{}", cell_line(at + 1, total, cell, row));
        }
    }
    text
}

/// One line for a finished cell: where it is in the plan, what it is, and its result; a
/// contended cell ends with the word `contended`.
pub fn cell_line(position: usize, total: usize, cell: &Cell, row: &SummaryRow) -> String {
    let width = total.to_string().len();
    let mut line = format!("[{position:>width$}/{total}] {:<36}", cell.label());
    match (row.status, row.mean_s) {
        (Status::Ok, Some(mean)) => {
            let p = places(mean);
            let _ = write!(line, " {mean:>10.p$} s");
            if let Some(sd) = row.stddev_s {
                let _ = write!(line, " ± {sd:.p$}");
            }
            if let Some(speedup) = row.speedup {
                let _ = write!(line, "  speedup {speedup:.2}×");
                if let (Some(lo), Some(hi)) = (row.speedup_ci_low, row.speedup_ci_high) {
                    let _ = write!(line, " [{lo:.2}–{hi:.2}]");
                }
            }
            if row.outliers.unwrap_or(0) > 0 {
                let _ = write!(
                    line,
                    "  {}",
                    plural(row.outliers.unwrap_or(0), "outlier", "outliers")
                );
            }
        }
        _ => {
            let _ = write!(line, " FAILED: {}", row.reason);
        }
    }
    if row.oversubscribed {
        line.push_str("  oversubscribed");
    }
    if row.contended == Some(true) {
        line.push_str("  contended");
    }
    line
}

/// The warning before the plan when other work already keeps the machine busy.
pub fn busy_warning(busy_threads: f64, hardware_threads: usize) -> String {
    format!(
        "warning: {busy_threads:.1} of {hardware_threads} cores busy with other work: timings will \
         not be trustworthy (cells that see it are marked contended=true in summary.csv; \
         --wait-quiet SECONDS waits for a quiet machine before each round)"
    )
}

/// Printed when `--wait-quiet` starts waiting before a round of `label`.
pub fn waiting(label: &str, busy: Option<f64>, hardware_threads: usize, bound: Duration) {
    crate::output::console::warn(&format!(
        "{label}: {} of {hardware_threads} hardware threads busy with other work; waiting up \
         to {} for a quiet machine (--wait-quiet)",
        busy.map_or_else(|| "?".to_owned(), |b| format!("{b:.1}")),
        duration(bound.as_secs_f64())
    ));
}

/// Printed when the wait ends: quiet, or still busy and measuring anyway.
pub fn waited(quiet: bool, after: Duration, busy: Option<f64>) {
    let after = duration(after.as_secs_f64());
    crate::output::console::warn(&if quiet {
        format!("  quiet after {after}: measuring")
    } else {
        format!(
            "  still busy after {after} ({} threads): measuring anyway; the cells will be \
             marked contended",
            busy.map_or_else(|| "?".to_owned(), |b| format!("{b:.1}"))
        )
    });
}

/// The warning after a sweep naming its contended cells, if any, and what to do.
pub fn contended_cells(dir: &std::path::Path, rows: &[SummaryRow]) -> Option<String> {
    let names: Vec<String> = rows
        .iter()
        .filter(|r| r.contended == Some(true))
        .map(|r| format!("{} ({})", r.key().label_with_group(), r.phase.as_str()))
        .collect();
    if names.is_empty() {
        return None;
    }
    let mut text = format!(
        "warning: {} saw other work on the machine (contended=true in summary.csv): their \
         times are not trustworthy and the report leaves them out of its findings. To measure \
         their groups again: bench-sph sweep --resume {} --remeasure-contended (add \
         --wait-quiet 60 to wait for a quiet machine before each round). Contended:",
        plural(names.len(), "cell", "cells"),
        dir.display()
    );
    for name in names {
        let _ = write!(text, "\n  {name}");
    }
    Some(text)
}

/// The line that says whether the first run of a round was slower than the same cell's other
/// runs ([`crate::results::summarize::first_run_effect`]).
pub fn first_run_line(effect: crate::results::intervals::Ratio) -> String {
    let interval = effect
        .interval
        .map_or_else(String::new, |i| format!(" [{:.3}–{:.3}]", i.low, i.high));
    let verdict = match effect.interval {
        None => "too few rounds to tell",
        Some(_) if !effect.resolved() => "no different",
        Some(_) if effect.value > 1.0 => "SLOWER: the warm-up falls short (try --warmup 3)",
        Some(_) => "faster",
    };
    format!(
        "First run of each round against the same cell's other runs: {:.3}×{interval} over {} \
         rounds: {verdict}",
        effect.value, effect.rounds
    )
}

/// The fastest finished cell of each strategy in each group, as a table, groups in plan
/// order and strategies in registry order. `rows` may hold any number of sessions' rows.
/// Where a group has confirmation rows, only those compete: they did not choose the cells.
pub fn best_cells(plan: &Plan, rows: &[SummaryRow]) -> String {
    let mut text = String::new();
    for group in &plan.groups {
        let confirmed = rows
            .iter()
            .any(|r| r.group() == *group && r.phase == Phase::Confirm);
        let phase = if confirmed {
            Phase::Confirm
        } else {
            Phase::Grid
        };
        let by_key: HashMap<Cell, &SummaryRow> = rows
            .iter()
            .filter(|r| r.phase == phase)
            .map(|r| (r.key(), r))
            .collect();
        let _ = writeln!(
            text,
            "Fastest cell per strategy ({}; {}):",
            group.label(LabelStyle::Sweep),
            if confirmed {
                "from the confirmation rounds, which did not choose the cells"
            } else {
                "from the grid rounds that chose them: biased fast"
            }
        );
        // With several placements, one row per (strategy, pin), named `strategy (pin)`.
        let mut lines: Vec<(StrategyName, Pin)> = plan
            .cells
            .iter()
            .filter(|c| c.group == *group)
            .map(|c| (c.strategy, c.pin))
            .collect();
        lines.sort_by_key(|&(s, p)| (plan.cells.iter().position(|c| c.strategy == s), p));
        lines.dedup();
        let pinned = lines.iter().any(|&(_, p)| p != Pin::None);
        let w = if pinned { 24 } else { 16 };
        let _ = writeln!(
            text,
            "  {:<w$} {:>5} {:>6} {:>10} {:>10} {:>19} {:>10}",
            "strategy", "cores", "chunks", "mean s", "stddev s", "speedup [95 %]", "efficiency"
        );
        for (strategy, pin) in lines {
            let name = match pin {
                Pin::None => strategy.as_str().to_owned(),
                pin => format!("{strategy} ({pin})"),
            };
            let best = fastest(
                plan.cells
                    .iter()
                    .filter(|c| c.group == *group && c.strategy == strategy && c.pin == pin)
                    .filter_map(|c| by_key.get(c).copied()),
                Contended::Compete,
            );
            let num = |v: Option<f64>, prec: usize| {
                v.map_or_else(|| "-".to_owned(), |v| format!("{v:.prec$}"))
            };
            match best {
                Some(r) => {
                    let speedup = match (r.speedup, r.speedup_ci_low, r.speedup_ci_high) {
                        (Some(s), Some(lo), Some(hi)) => format!("{s:.2} [{lo:.2}–{hi:.2}]"),
                        (s, _, _) => num(s, 2),
                    };
                    let _ = writeln!(
                        text,
                        "  {:<w$} {:>5} {:>6} {:>10} {:>10} {:>19} {:>10}",
                        name,
                        r.cores,
                        r.chunks.map_or_else(|| "-".to_owned(), |k| k.to_string()),
                        num(r.mean_s, places(r.mean_s.unwrap_or(0.0))),
                        num(r.stddev_s, places(r.mean_s.unwrap_or(0.0))),
                        speedup,
                        num(r.efficiency, 2),
                    );
                }
                None => {
                    let _ = writeln!(
                        text,
                        "  {name:<w$} {}",
                        unconfirmed(rows, group, strategy, pin)
                    );
                }
            }
        }
    }
    text
}

/// What the best-cell table says of a strategy with no row in its phase: a strategy the
/// confirmation left out (its best grid cell took more than
/// [`OUT_OF_THE_RUNNING`](super::confirm::OUT_OF_THE_RUNNING) times the fastest's mean) is named
/// as such, with its grid figure; only a strategy none of whose cells finished has no
/// successful cell.
fn unconfirmed(
    rows: &[SummaryRow],
    group: &plan::Group,
    strategy: StrategyName,
    pin: Pin,
) -> String {
    let grid = rows.iter().filter(|r| {
        r.phase == Phase::Grid && r.group() == *group && r.strategy == strategy && r.pin == pin
    });
    match fastest(grid, Contended::Compete) {
        Some(r) => format!(
            "not confirmed: out of the running in the grid rounds (best {} at {}, biased fast)",
            r.speedup
                .map_or_else(|| "-".to_owned(), |s| format!("{s:.2}× over seq")),
            plural(r.cores, "core", "cores"),
        ),
        None => "(no successful cell)".to_owned(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sweep::params::SweepParams;
    use sph_solver::sph::neighbors::NeighborMode;

    fn plan() -> Plan {
        Plan::new(&SweepParams {
            cores: vec![1, 2, 3],
            warmup: 1,
            ..SweepParams::small()
        })
    }

    #[test]
    fn the_plan_says_which_cores_use_smt_siblings_on_an_smt_machine_and_nothing_without_smt() {
        use crate::topology::{Topology, fake};
        let mut params = SweepParams {
            neighbors: vec![NeighborMode::Grid],
            cores: vec![1, 2, 4, 6, 8, 10],
            chunks: vec![5],
            trials: 1,
            pin: vec![Pin::Compact, Pin::Spread],
            ..SweepParams::small()
        };
        // 4 cores × 2 threads.
        let smt = Topology::read(fake::smt_4x2().root(), &[0, 1, 2, 3, 4, 5, 6, 7]);
        let note = placement_note(&params, &smt).unwrap();
        assert!(note.contains("placements: compact, spread"), "{note}");
        assert!(
            note.contains("4 physical cores and 8 hardware threads"),
            "{note}"
        );
        assert!(note.contains("cores 6, 8 use SMT siblings"), "{note}");
        assert!(
            note.contains("at 10 cores, spread puts 4 threads on physical cores and 4 on siblings"),
            "{note}"
        );
        // Only the first core of each pair allowed: no siblings, nothing to say but the pins.
        let no_smt = Topology::read(fake::smt_4x2().root(), &[0, 1, 2, 3]);
        assert_eq!(
            placement_note(&params, &no_smt).as_deref(),
            Some("  placements: compact, spread (each a cell; seq, the reference, runs unpinned)")
        );
        params.pin = vec![Pin::None];
        assert_eq!(placement_note(&params, &no_smt), None);
    }

    fn row(cell: &Cell, walls: &[f64], failure: Option<&str>) -> SummaryRow {
        use crate::results::fixtures;
        use crate::results::summarize::{CellContext, summary_row};
        let trials = fixtures::trials(cell, walls);
        let seq = fixtures::trials(&Cell::reference(cell.group), &vec![4.0; walls.len()]);
        let ctx = CellContext {
            hardware_threads: 2,
            shard: None,
            smt: None,
        };
        summary_row(cell, Phase::Grid, &trials, Some(&seq), failure, &ctx)
    }

    #[test]
    fn durations_read_naturally() {
        assert_eq!(duration(0.00025), "0.25 ms");
        assert_eq!(duration(0.0123), "12 ms");
        assert_eq!(duration(4.24), "4.2 s");
        assert_eq!(duration(42.4), "42 s");
        assert_eq!(duration(200.0), "3 min 20 s");
        assert_eq!(duration(3900.0), "1 h 05 min");
        assert_eq!(duration(f64::NAN), "unknown");
        assert_eq!(duration(-0.0), "0 ms", "an empty sum of floats is -0.0");
        assert_eq!(duration(std::iter::empty::<f64>().sum()), "0 ms");
    }

    #[test]
    fn times_show_four_significant_digits() {
        assert_eq!(format!("{:.*}", places(0.1361), 0.1361), "0.1361");
        assert_eq!(format!("{:.*}", places(0.0000694), 0.0000694), "0.00006940");
        assert_eq!(format!("{:.*}", places(12.3), 12.3), "12.30");
        assert_eq!(places(12345.0), 1);
    }

    #[test]
    fn cores_beyond_the_hardware_threads_are_named_in_a_warning() {
        let w = oversubscription_warning(&plan(), 2).unwrap();
        assert!(w.contains("cores 3 exceed"), "{w}");
        assert!(w.contains("2 cells"), "{w}");
        assert_eq!(oversubscription_warning(&plan(), 3), None);
    }

    #[test]
    fn a_cell_line_shows_its_result_or_its_failure() {
        let p = plan();
        let cell = p.cells[1];
        let ok = cell_line(2, 7, &cell, &row(&cell, &[1.0, 3.0], None));
        assert!(
            ok.starts_with("[2/7] rayon-chunks, 1 core, 2 chunks"),
            "{ok}"
        );
        // Paired with seq's 4 s: ratios 4 and 4/3, geometric mean √(16/3).
        assert!(
            ok.contains("2.000 s ± 1.414") && ok.contains("speedup 2.31×"),
            "{ok}"
        );
        assert!(!ok.contains("× ["), "two rounds give no interval: {ok}");
        let three = cell_line(2, 7, &cell, &row(&cell, &[2.0, 2.0, 2.0], None));
        assert!(three.contains("speedup 2.00× [2.00–2.00]"), "{three}");
        let mut contended = row(&cell, &[1.0, 3.0], None);
        contended.contended = Some(true);
        assert!(cell_line(2, 7, &cell, &contended).ends_with("  contended"));
        let bad = cell_line(2, 7, &cell, &row(&cell, &[1.0], Some("trial 1: boom")));
        assert!(bad.contains("FAILED: trial 1: boom"), "{bad}");
    }

    #[test]
    fn the_best_cell_table_picks_the_lowest_mean_among_successful_cells() {
        let p = plan();
        let rows: Vec<SummaryRow> = vec![
            row(&p.cells[0], &[4.0], None),
            row(&p.cells[1], &[3.0], None),
            row(&p.cells[2], &[1.0], Some("checksum differs")),
            row(&p.cells[3], &[2.0], None),
        ];
        let text = best_cells(&p, &rows);
        let line = text
            .lines()
            .find(|l| l.trim_start().starts_with("rayon-chunks"))
            .unwrap();
        assert!(line.contains("2.000"), "{text}");
        assert!(text.contains("seq"), "{text}");
    }

    #[test]
    fn a_strategy_the_confirmation_left_out_is_named_so_not_called_unsuccessful() {
        let p = Plan::new(&SweepParams {
            strategies: vec![StrategyName::RayonChunks, StrategyName::RayonSpawn],
            cores: vec![1],
            ..SweepParams::small()
        });
        let strategy = |s| {
            let at = p.cells.iter().position(|c| c.strategy.as_str() == s);
            at.map(|at| &p.cells[at]).unwrap()
        };
        let (seq, fast, slow) = (
            &p.cells[0],
            strategy("rayon-chunks"),
            strategy("rayon-spawn"),
        );
        let grid = |cell, walls: &[f64]| row(cell, walls, None);
        let confirm = |cell, walls: &[f64]| SummaryRow {
            phase: Phase::Confirm,
            ..row(cell, walls, None)
        };
        let mut rows = vec![grid(seq, &[4.0]), grid(fast, &[2.0]), grid(slow, &[16.0])];
        rows.extend([confirm(seq, &[4.0]), confirm(fast, &[2.0])]);
        let text = best_cells(&p, &rows);
        let line = |s: &str| {
            let found = text.lines().find(|l| l.trim_start().starts_with(s));
            found.unwrap().to_owned()
        };
        assert!(line("rayon-chunks").contains("2.000"), "{text}");
        let spawn = line("rayon-spawn");
        assert!(spawn.contains("not confirmed"), "{text}");
        assert!(spawn.contains("best 0.25× over seq at 1 core"), "{text}");
        // A strategy none of whose cells finished has no successful cell.
        rows[2] = row(slow, &[16.0], Some("boom"));
        let text = best_cells(&p, &rows);
        assert!(
            text.contains("rayon-spawn") && text.contains("(no successful cell)"),
            "{text}"
        );
    }
}
