//! What a trace adds up to: per worker busy time, idle share and kernel calls; per pass the
//! load imbalance; in total the tasks created (the analogue of the GHC runtime's `SPARKS:`
//! line). Pure functions of a [`Trace`], and the `stats.csv` exporter.

use std::collections::BTreeMap;
use std::io::Write;

use super::files::StatsRow;
use super::recorder::{Phase, Trace};

/// The header of `stats.csv`.
pub const CSV_HEADER: &str = "kind,name,threads,kernel_calls,busy_ms,span_ms,idle_pct,imbalance";

/// One worker track.
#[derive(Debug, Clone, PartialEq)]
pub struct WorkerStats {
    /// Worker index.
    pub worker: usize,
    /// The OS threads that held this worker slot, in order (one for a pool's thread; a fresh
    /// one per pass for `std-static`).
    pub threads: Vec<String>,
    /// Kernel calls (chunks) it ran.
    pub kernel_calls: usize,
    /// Nanoseconds spent inside kernel calls.
    pub busy_ns: u64,
    /// Percentage of the step loop's wall time it spent outside kernel calls.
    pub idle_pct: f64,
}

impl WorkerStats {
    /// `worker-name` if one thread held the slot, else `k threads`.
    pub fn thread_label(&self) -> String {
        match self.threads.as_slice() {
            [] => "idle".to_owned(),
            [one] => one.clone(),
            many => format!("{} threads", many.len()),
        }
    }
}

/// One pass (or the grid rebuild's kernel calls), over all traced steps.
#[derive(Debug, Clone, PartialEq)]
pub struct PassStats {
    /// The pass.
    pub phase: Phase,
    /// Kernel calls over all steps.
    pub kernel_calls: usize,
    /// Fewest and most kernel calls in one step.
    pub calls_per_step: (usize, usize),
    /// Nanoseconds inside this pass's kernel calls, summed over workers and steps.
    pub busy_ns: u64,
    /// Nanoseconds from the first call's start to the last call's end, summed over steps.
    pub span_ns: u64,
    /// Percentage of `workers × span` that no worker spent in this pass's kernels.
    pub idle_pct: f64,
    /// Load imbalance: the busiest worker's kernel time over the mean over all workers, per
    /// step, averaged over steps (1 = perfectly balanced; `workers` = one worker did it all).
    /// `None` when no kernel call took measurable time.
    pub imbalance: Option<f64>,
}

/// The run as a whole.
#[derive(Debug, Clone, PartialEq)]
pub struct TotalStats {
    /// Kernel calls over all passes and steps: the tasks the strategy created.
    pub kernel_calls: usize,
    /// Distinct OS threads that ran kernel calls.
    pub worker_threads: usize,
    /// Worker tracks that ran at least one kernel call (see [`idle_workers_note`]).
    pub workers_used: usize,
    /// Nanoseconds inside kernel calls, summed over workers.
    pub busy_ns: u64,
    /// Nanoseconds of serial work (grid rebuild, divergence check) on the calling thread.
    pub serial_ns: u64,
    /// Wall nanoseconds of the step loop.
    pub wall_ns: u64,
    /// Percentage of `workers × wall` spent outside kernel calls.
    pub idle_pct: f64,
}

/// Everything `stats.csv` and the printed summary hold.
#[derive(Debug, Clone, PartialEq)]
pub struct Stats {
    /// One entry per worker track, by index.
    pub workers: Vec<WorkerStats>,
    /// One entry per pass, in step order, after one for the grid rebuild's kernel calls when
    /// there were any (only with the grid neighbour search).
    pub passes: Vec<PassStats>,
    /// The totals.
    pub total: TotalStats,
}

/// `100 × (1 − busy / capacity)`, 0 when there is no capacity.
fn idle_pct(busy_ns: u64, capacity_ns: u64) -> f64 {
    if capacity_ns == 0 {
        return 0.0;
    }
    (100.0 * (1.0 - busy_ns as f64 / capacity_ns as f64)).max(0.0)
}

/// Adds up `trace`.
pub fn compute(trace: &Trace) -> Stats {
    let n_workers = trace.workers;
    let mut workers: Vec<WorkerStats> = (0..n_workers)
        .map(|worker| WorkerStats {
            worker,
            threads: trace
                .threads
                .iter()
                .filter(|t| t.worker == worker)
                .map(|t| t.name.clone())
                .collect(),
            kernel_calls: 0,
            busy_ns: 0,
            idle_pct: 0.0,
        })
        .collect();
    for e in &trace.kernels {
        let w = &mut workers[e.worker];
        w.kernel_calls += 1;
        w.busy_ns += e.duration_ns();
    }
    for w in &mut workers {
        w.idle_pct = idle_pct(w.busy_ns, trace.wall_ns);
    }
    let passes = trace
        .phases()
        .into_iter()
        .map(|p| pass_stats(trace, p))
        .collect();
    let busy_ns = workers.iter().map(|w| w.busy_ns).sum();
    let total = TotalStats {
        kernel_calls: trace.kernels.len(),
        worker_threads: trace.threads.len(),
        workers_used: workers.iter().filter(|w| w.kernel_calls > 0).count(),
        busy_ns,
        serial_ns: trace.serial.iter().map(|e| e.end_ns - e.start_ns).sum(),
        wall_ns: trace.wall_ns,
        idle_pct: idle_pct(busy_ns, n_workers as u64 * trace.wall_ns),
    };
    Stats {
        workers,
        passes,
        total,
    }
}

/// The plain fact when only `used` of the trace's `workers` worker tracks ran kernel calls,
/// or `None` when every one did. A timeline on one worker shows no parallel execution, and
/// the summary and the report say so rather than explain the idle share.
pub fn idle_workers_note(used: usize, workers: usize) -> Option<String> {
    if used >= workers {
        return None;
    }
    let shows = if used <= 1 {
        "the timeline does not show parallel execution".to_owned()
    } else {
        format!("the timeline shows at most {used} of them running at once")
    };
    Some(format!(
        "only {used} of {workers} workers ran kernels in the recorded steps; {shows}"
    ))
}

/// Per step of one pass: kernel calls, busy time per worker, first start and last end.
struct PassInstance {
    calls: usize,
    busy: Vec<u64>,
    start: u64,
    end: u64,
}

fn pass_stats(trace: &Trace, phase: Phase) -> PassStats {
    let mut steps: BTreeMap<usize, PassInstance> = BTreeMap::new();
    for e in trace.kernels.iter().filter(|e| e.phase == phase) {
        let inst = steps.entry(e.step).or_insert_with(|| PassInstance {
            calls: 0,
            busy: vec![0; trace.workers],
            start: e.start_ns,
            end: e.end_ns,
        });
        inst.calls += 1;
        inst.busy[e.worker] += e.duration_ns();
        inst.start = inst.start.min(e.start_ns);
        inst.end = inst.end.max(e.end_ns);
    }
    let busy_ns = steps.values().flat_map(|s| &s.busy).sum();
    let span_ns = steps.values().map(|s| s.end - s.start).sum();
    let ratios: Vec<f64> = steps
        .values()
        .filter_map(|s| {
            let total: u64 = s.busy.iter().sum();
            let max = *s.busy.iter().max()?;
            (total > 0).then(|| max as f64 / (total as f64 / s.busy.len() as f64))
        })
        .collect();
    PassStats {
        phase,
        kernel_calls: steps.values().map(|s| s.calls).sum(),
        calls_per_step: (
            steps.values().map(|s| s.calls).min().unwrap_or(0),
            steps.values().map(|s| s.calls).max().unwrap_or(0),
        ),
        busy_ns,
        span_ns,
        idle_pct: idle_pct(busy_ns, trace.workers as u64 * span_ns),
        imbalance: (!ratios.is_empty()).then(|| ratios.iter().sum::<f64>() / ratios.len() as f64),
    }
}

fn ms(ns: u64) -> f64 {
    ns as f64 / 1e6
}

/// Writes `stats.csv` (header [`CSV_HEADER`]): one `worker` row per worker track (`name` the worker
/// index, `threads` how many OS threads held it, `span_ms` the step loop's wall time), one `pass`
/// row per pass (`name` the model's passes, Müller's density and forces, preceded by `grid rebuild`
/// when the grid's rebuild ran kernel calls; `span_ms` summed over steps, `imbalance` as in
/// [`PassStats`]), and one `total` row (`threads` the distinct worker threads, `kernel_calls` the
/// tasks created). Times in milliseconds, idle shares in percent; empty where a column does not
/// apply.
pub fn write_csv<W: Write>(stats: &Stats, out: W) -> Result<(), csv::Error> {
    let mut w = csv::Writer::from_writer(out);
    for s in &stats.workers {
        w.serialize(StatsRow {
            kind: "worker".to_owned(),
            name: s.worker.to_string(),
            threads: Some(s.threads.len()),
            kernel_calls: s.kernel_calls,
            busy_ms: ms(s.busy_ns),
            span_ms: ms(stats.total.wall_ns),
            idle_pct: s.idle_pct,
            imbalance: None,
        })?;
    }
    for p in &stats.passes {
        w.serialize(StatsRow {
            kind: "pass".to_owned(),
            name: p.phase.as_str().to_owned(),
            threads: None,
            kernel_calls: p.kernel_calls,
            busy_ms: ms(p.busy_ns),
            span_ms: ms(p.span_ns),
            idle_pct: p.idle_pct,
            imbalance: p.imbalance,
        })?;
    }
    let t = &stats.total;
    w.serialize(StatsRow {
        kind: "total".to_owned(),
        name: "all".to_owned(),
        threads: Some(t.worker_threads),
        kernel_calls: t.kernel_calls,
        busy_ms: ms(t.busy_ns),
        span_ms: ms(t.wall_ns),
        idle_pct: t.idle_pct,
        imbalance: None,
    })?;
    w.flush()?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::trace::recorder::{KernelEvent, SerialEvent, SerialWork, ThreadInfo};
    use sph_solver::solver::Pass;

    fn k(pass: Pass, step: usize, worker: usize, start_ns: u64, end_ns: u64) -> KernelEvent {
        KernelEvent {
            phase: Phase::Pass(pass),
            step,
            worker,
            thread: worker,
            first: 0,
            len: 1,
            start_ns,
            end_ns,
        }
    }

    /// Two workers, 1000 ns of step loop: worker 0 busy 600 ns, worker 1 busy 200 ns.
    fn two_workers() -> Trace {
        Trace {
            kernels: vec![
                k(Pass::Density, 1, 0, 0, 300),
                k(Pass::Density, 1, 1, 0, 100),
                k(Pass::Forces, 1, 0, 300, 500),
                k(Pass::Forces, 1, 1, 300, 400),
                k(Pass::Forces, 1, 0, 500, 600),
            ],
            serial: vec![SerialEvent {
                work: SerialWork::Check,
                step: 1,
                start_ns: 600,
                end_ns: 650,
            }],
            threads: vec![
                ThreadInfo {
                    name: "pool-0".into(),
                    worker: 0,
                },
                ThreadInfo {
                    name: "pool-1".into(),
                    worker: 1,
                },
            ],
            workers: 2,
            wall_ns: 1000,
        }
    }

    #[test]
    fn workers_add_up_busy_time_calls_and_idle_share_of_the_wall_time() {
        let s = compute(&two_workers());
        assert_eq!(s.workers[0].busy_ns, 600);
        assert_eq!(s.workers[0].kernel_calls, 3);
        assert_eq!(s.workers[0].idle_pct, 40.0);
        assert_eq!(s.workers[1].busy_ns, 200);
        assert_eq!(s.workers[1].idle_pct, 80.0);
        assert_eq!(s.workers[1].thread_label(), "pool-1");
    }

    #[test]
    fn imbalance_is_the_busiest_worker_over_the_mean_worker() {
        let s = compute(&two_workers());
        // density: 300 vs 100 -> 300 / 200; forces: 200 + 100 vs 100 -> 300 / 200.
        let imb: Vec<f64> = s.passes.iter().map(|p| p.imbalance.unwrap()).collect();
        assert_eq!(imb, [1.5, 1.5]);
        // All of a pass on one worker: as unbalanced as two workers can be.
        let mut t = two_workers();
        t.kernels.retain(|e| e.worker == 0);
        let imb: Vec<f64> = compute(&t)
            .passes
            .iter()
            .map(|p| p.imbalance.unwrap())
            .collect();
        assert_eq!(imb, [2.0, 2.0]);
        assert_eq!(s.passes[0].span_ns, 300);
        assert_eq!(s.passes[0].busy_ns, 400);
        assert!((s.passes[0].idle_pct - 100.0 / 3.0).abs() < 1e-12);
    }

    #[test]
    fn imbalance_is_averaged_over_steps_not_summed_busy_time() {
        let mut t = two_workers();
        t.kernels = vec![
            k(Pass::Density, 1, 0, 0, 300),
            k(Pass::Density, 1, 1, 0, 100),
            k(Pass::Density, 2, 0, 400, 500),
            k(Pass::Density, 2, 1, 400, 700),
        ];
        let d = &compute(&t).passes[0];
        // Per step 1.5 and 1.5; summed busy would be 400 vs 400 (= 1).
        assert_eq!(d.imbalance, Some(1.5));
        assert_eq!(d.calls_per_step, (2, 2));
        assert_eq!(d.span_ns, 300 + 300);
    }

    #[test]
    fn totals_count_every_kernel_call_as_a_task_and_every_thread() {
        let s = compute(&two_workers());
        assert_eq!(s.total.kernel_calls, 5);
        assert_eq!(s.total.worker_threads, 2);
        assert_eq!(s.total.busy_ns, 800);
        assert_eq!(s.total.serial_ns, 50);
        assert_eq!(s.total.idle_pct, 60.0);
    }

    #[test]
    fn a_pass_without_calls_has_no_imbalance_and_an_idle_worker_no_threads() {
        let mut t = two_workers();
        t.kernels
            .retain(|e| e.phase != Phase::Pass(Pass::Forces) && e.worker == 0);
        t.threads.truncate(1);
        let s = compute(&t);
        assert_eq!(s.passes[1].imbalance, None);
        assert_eq!(s.passes[1].kernel_calls, 0);
        assert_eq!(s.workers[1].thread_label(), "idle");
        assert_eq!(s.workers[1].idle_pct, 100.0);
        assert_eq!((s.total.workers_used, s.workers.len()), (1, 2));
    }

    #[test]
    fn a_trace_where_only_some_workers_ran_says_so_plainly() {
        assert_eq!(idle_workers_note(2, 2), None);
        assert_eq!(
            idle_workers_note(1, 2).unwrap(),
            "only 1 of 2 workers ran kernels in the recorded steps; the timeline does not show \
             parallel execution"
        );
        assert_eq!(
            idle_workers_note(3, 4).unwrap(),
            "only 3 of 4 workers ran kernels in the recorded steps; the timeline shows at most 3 \
             of them running at once"
        );
    }

    #[test]
    fn the_grid_rebuild_gets_its_own_row_only_when_it_ran_kernel_calls() {
        assert_eq!(compute(&two_workers()).passes.len(), 2);
        let mut t = two_workers();
        t.kernels.push(KernelEvent {
            phase: Phase::Rebuild,
            ..k(Pass::Density, 1, 1, 650, 700)
        });
        let s = compute(&t);
        let names: Vec<&str> = s.passes.iter().map(|p| p.phase.as_str()).collect();
        assert_eq!(names, ["grid rebuild", "density", "forces"]);
        assert_eq!(s.workers[1].busy_ns, 250);
    }

    #[test]
    fn the_csv_has_the_documented_columns_and_one_row_per_worker_pass_and_total() {
        let mut bytes = Vec::new();
        write_csv(&compute(&two_workers()), &mut bytes).unwrap();
        let text = String::from_utf8(bytes).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines[0], CSV_HEADER);
        assert_eq!(lines.len(), 1 + 2 + 2 + 1);
        assert_eq!(lines[1], "worker,0,1,3,0.0006,0.001,40.0,");
        assert_eq!(
            lines[3],
            "pass,density,,2,0.0004,0.0003,33.333333333333336,1.5"
        );
        assert_eq!(lines[5], "total,all,2,5,0.0008,0.001,60.0,");
    }
}
