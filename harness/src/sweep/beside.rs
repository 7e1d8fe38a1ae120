//! What a sweep measures beside its cells, once they are all measured: what a pass costs each
//! strategy at each core count (`--pass-cost`, [`crate::run::pass_cost`]) and the OpenMP
//! anchor (`--anchor`, [`super::anchor`]). Each is written whole, under a temporary name and
//! renamed, into the results directory; a sweep stopped while they run writes neither and ends
//! as interrupted, so that `--resume` measures them.

use std::path::Path;
use std::time::Duration;

use anyhow::Context;
use serde::Serialize;

use super::anchor;
use super::params::SweepParams;
use super::plan::Plan;
use crate::output::atomic;
use crate::results::anchor::{AnchorRun, same_state, speedups};
use crate::results::key::LabelStyle;
use crate::results::rows::{Phase, SummaryRow};
use crate::results::{ANCHOR_FILE, PASS_COST_FILE};
use crate::run::pass_cost;

/// The work of a pass per thread in `pass-cost.csv`: enough that every thread takes its chunk
/// (see [`pass_cost`]), little enough that the cost shows.
pub const PASS_WORK: Duration = Duration::from_micros(5);
/// Passes per round of `pass-cost.csv`, and `bench-sph overhead`'s default.
pub const PASS_PASSES: u64 = 1000;
/// Rounds of `pass-cost.csv`, and `bench-sph overhead`'s default.
pub const PASS_ROUNDS: usize = 10;

/// Measures what `params` asks beside the cells into `dir`, the finished cells being `rows`;
/// returns `false` when a signal stopped it (nothing written).
pub fn measure(
    dir: &Path,
    plan: &Plan,
    params: &SweepParams,
    rows: &[&SummaryRow],
    hardware: usize,
) -> anyhow::Result<bool> {
    if params.pass_cost {
        let cells = pass_cost::cells(&params.strategies, &params.cores);
        super::print(&format!(
            "measuring what a pass costs {} strategy × core count cells ({} µs of work a \
             thread, {PASS_ROUNDS} rounds of {PASS_PASSES} passes) ...",
            cells.len(),
            PASS_WORK.as_micros()
        ));
        let Some(table) = pass_cost::table(
            &cells,
            PASS_WORK,
            PASS_PASSES,
            PASS_ROUNDS,
            hardware,
            crate::signals::requested,
        )?
        else {
            return Ok(false);
        };
        write_csv(&dir.join(PASS_COST_FILE), &table)?;
    }
    if let Some(path) = &params.anchor {
        let mut runs: Vec<AnchorRun> = Vec::new();
        for group in plan.groups.iter().filter(|g| anchor::applies(g)) {
            let seq = rows
                .iter()
                .find(|r| r.group() == *group && r.phase == Phase::Grid && r.is_reference());
            let seq_s = seq.and_then(|r| r.mean_s).unwrap_or(1.0);
            // The plain loop runs at about bench-sph's pace; a program that takes fifty times
            // seq's time (and at least a minute) is stopped as hung.
            let limit = Duration::from_secs_f64((50.0 * seq_s).max(60.0));
            super::print(&format!(
                "running the OpenMP anchor '{}' for {} ...",
                path.display(),
                group.label(LabelStyle::Sweep)
            ));
            let Some(group_runs) =
                anchor::measure(path, group, &params.cores, params, hardware, limit)?
            else {
                return Ok(false);
            };
            super::print(&anchor_text(&group_runs, group.n, group.steps, seq));
            runs.extend(group_runs);
        }
        write_csv(&dir.join(ANCHOR_FILE), &runs)?;
    }
    Ok(true)
}

/// What the console says of a group's anchor runs: each speedup, and whether it computed
/// `seq`'s state.
fn anchor_text(runs: &[AnchorRun], n: usize, steps: usize, seq: Option<&&SummaryRow>) -> String {
    let same = seq.is_some_and(|r| same_state(runs, n, steps, &r.checksum));
    if !same {
        return "  ⚠ the anchor did not compute seq's state (another checksum): the report \
                does not set its speedups beside the strategies'"
            .to_string();
    }
    let cells: Vec<String> = speedups(runs, n, steps)
        .iter()
        .map(|s| {
            let interval = s
                .speedup
                .interval
                .map_or(String::new(), |i| format!(" [{:.2}–{:.2}]", i.low, i.high));
            format!("{} threads {:.2}×{interval}", s.threads, s.speedup.value)
        })
        .collect();
    format!("  OpenMP anchor, paired speedup: {}", cells.join(", "))
}

/// Writes `rows` as a CSV file at `path`, under a temporary name and renamed.
fn write_csv<R: Serialize>(path: &Path, rows: &[R]) -> anyhow::Result<()> {
    let mut w = csv::Writer::from_writer(Vec::new());
    for r in rows {
        w.serialize(r)?;
    }
    let bytes = w
        .into_inner()
        .map_err(|e| anyhow::anyhow!("{}", e.error()))?;
    atomic::write(path, &bytes).with_context(|| format!("cannot write '{}'", path.display()))
}
