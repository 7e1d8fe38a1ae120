//! `trace.json`: the trace in Chrome's trace-event format, which Perfetto
//! (<https://ui.perfetto.dev>) and `chrome://tracing` open.
//!
//! One process; one track (`tid`) per worker, named `worker k (thread)`, and one more track,
//! `serial (between passes)`, for the grid rebuild and divergence check done between passes by the
//! thread that drives the steps. Each kernel call is one complete event (`"ph": "X"`) named
//! after its pass, with category `pass` (or named `grid rebuild`, category `rebuild`, for the
//! grid's rebuild kernels), `ts`/`dur` in microseconds from the start of the step loop, and
//! `args` {`step`, `first`, `len`, `worker`, `thread`}; serial work has category `serial`. Step starts are global instant events (`"ph": "i"`) named `step k`.

use std::io::Write;

use serde::Serialize;

use super::TraceConfig;
use super::recorder::{Phase, Trace};
use super::stats::WorkerStats;

const PID: u32 = 1;

#[derive(Serialize)]
struct File<'a> {
    #[serde(rename = "traceEvents")]
    trace_events: Vec<Event<'a>>,
    #[serde(rename = "displayTimeUnit")]
    display_time_unit: &'static str,
    #[serde(rename = "otherData")]
    other_data: &'a TraceConfig,
}

#[derive(Serialize)]
struct Event<'a> {
    name: &'a str,
    #[serde(skip_serializing_if = "Option::is_none")]
    cat: Option<&'static str>,
    ph: &'static str,
    #[serde(skip_serializing_if = "Option::is_none")]
    ts: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    dur: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    s: Option<&'static str>,
    pid: u32,
    tid: usize,
    #[serde(skip_serializing_if = "Args::is_none")]
    args: Args<'a>,
}

#[derive(Serialize)]
#[serde(untagged)]
enum Args<'a> {
    None,
    Name {
        name: String,
    },
    SortIndex {
        sort_index: usize,
    },
    Kernel {
        step: usize,
        first: usize,
        len: usize,
        worker: usize,
        thread: &'a str,
    },
    Serial {
        step: usize,
    },
}

impl Args<'_> {
    fn is_none(&self) -> bool {
        matches!(self, Args::None)
    }
}

/// Microseconds from nanoseconds.
fn us(ns: u64) -> f64 {
    ns as f64 / 1000.0
}

/// The name of worker `w`'s track.
pub fn worker_track_name(w: &WorkerStats) -> String {
    format!("worker {} ({})", w.worker, w.thread_label())
}

impl<'a> Event<'a> {
    /// A metadata event (`"ph": "M"`) about track `tid`.
    fn metadata(name: &'static str, tid: usize, args: Args<'a>) -> Self {
        Event {
            name,
            cat: None,
            ph: "M",
            ts: None,
            dur: None,
            s: None,
            pid: PID,
            tid,
            args,
        }
    }

    /// A complete event (`"ph": "X"`) from `start_ns` for `dur_ns` on track `tid`.
    fn complete(
        name: &'a str,
        cat: &'static str,
        (start_ns, dur_ns): (u64, u64),
        tid: usize,
        args: Args<'a>,
    ) -> Self {
        Event {
            name,
            cat: Some(cat),
            ph: "X",
            ts: Some(us(start_ns)),
            dur: Some(us(dur_ns)),
            s: None,
            pid: PID,
            tid,
            args,
        }
    }
}

/// Writes `trace` as Chrome trace-event JSON to `out`. `workers` names the worker tracks
/// (from [`super::stats::compute`]); `config` goes into `otherData`.
pub fn write<W: Write>(
    trace: &Trace,
    workers: &[WorkerStats],
    config: &TraceConfig,
    out: W,
) -> serde_json::Result<()> {
    let step_names: Vec<String> = (0..=config.steps).map(|s| format!("step {s}")).collect();
    let mut events = Vec::with_capacity(trace.kernels.len() + 2 * trace.serial.len() + 16);
    events.extend(track_events(trace, workers, config));
    events.extend(serial_events(trace, &step_names));
    events.extend(kernel_events(trace));
    serde_json::to_writer(
        out,
        &File {
            trace_events: events,
            display_time_unit: "ms",
            other_data: config,
        },
    )
}

/// The process's name, then each track's name and sort index: the workers', then the
/// caller's (`serial (between passes)`).
fn track_events(
    trace: &Trace,
    workers: &[WorkerStats],
    config: &TraceConfig,
) -> Vec<Event<'static>> {
    let process = format!("bench-sph trace: {}", config.title());
    let mut events = vec![Event::metadata(
        "process_name",
        0,
        Args::Name { name: process },
    )];
    let tracks = workers
        .iter()
        .map(|w| (w.worker, worker_track_name(w)))
        .chain([(trace.workers, "serial (between passes)".to_owned())]);
    for (tid, name) in tracks {
        events.push(Event::metadata("thread_name", tid, Args::Name { name }));
        let sort_index = Args::SortIndex { sort_index: tid };
        events.push(Event::metadata("thread_sort_index", tid, sort_index));
    }
    events
}

/// The caller's serial work on its own track, with a global instant event `step k` at each
/// step's start (its grid rebuild).
fn serial_events<'a>(trace: &Trace, step_names: &'a [String]) -> Vec<Event<'a>> {
    let caller = trace.workers;
    let mut events = Vec::with_capacity(2 * trace.serial.len());
    for e in &trace.serial {
        if e.work == super::SerialWork::Rebuild {
            events.push(Event {
                name: step_names.get(e.step).map_or("step", String::as_str),
                cat: Some("step"),
                ph: "i",
                ts: Some(us(e.start_ns)),
                dur: None,
                s: Some("g"),
                pid: PID,
                tid: caller,
                args: Args::None,
            });
        }
        let span = (e.start_ns, e.end_ns - e.start_ns);
        let args = Args::Serial { step: e.step };
        events.push(Event::complete(
            e.work.as_str(),
            "serial",
            span,
            caller,
            args,
        ));
    }
    events
}

/// Every kernel call on its worker's track.
fn kernel_events(trace: &Trace) -> impl Iterator<Item = Event<'_>> {
    trace.kernels.iter().map(|e| {
        let cat = match e.phase {
            Phase::Rebuild => "rebuild",
            Phase::Pass(_) => "pass",
        };
        let args = Args::Kernel {
            step: e.step,
            first: e.first,
            len: e.len,
            worker: e.worker,
            thread: trace.threads.get(e.thread).map_or("?", |t| t.name.as_str()),
        };
        let span = (e.start_ns, e.duration_ns());
        Event::complete(e.phase.as_str(), cat, span, e.worker, args)
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::trace::recorder::{KernelEvent, SerialEvent, SerialWork, ThreadInfo};
    use crate::trace::stats;
    use sph_solver::models::Preset;
    use sph_solver::solver::Pass;
    use sph_solver::sph::neighbors::NeighborMode;

    fn config() -> TraceConfig {
        TraceConfig {
            strategy: "rayon-chunks".into(),
            cores: 2,
            chunks: Some(2),
            n: 4,
            steps: 1,
            preset: Preset::Seed,
            neighbors: NeighborMode::AllPairs,
            seed: Some(2019),
            init: None,
        }
    }

    fn trace() -> Trace {
        let k = |worker, first, start_ns, end_ns| KernelEvent {
            phase: Phase::Pass(Pass::Density),
            step: 1,
            worker,
            thread: worker,
            first,
            len: 2,
            start_ns,
            end_ns,
        };
        Trace {
            kernels: vec![k(0, 0, 1500, 2500), k(1, 2, 1600, 2000)],
            serial: vec![SerialEvent {
                work: SerialWork::Rebuild,
                step: 1,
                start_ns: 0,
                end_ns: 1000,
            }],
            threads: vec![
                ThreadInfo {
                    name: "rayon-chunks-0".into(),
                    worker: 0,
                },
                ThreadInfo {
                    name: "rayon-chunks-1".into(),
                    worker: 1,
                },
            ],
            workers: 2,
            wall_ns: 3000,
        }
    }

    #[test]
    fn kernel_calls_become_complete_events_in_microseconds_on_their_worker_s_track() {
        let (t, c) = (trace(), config());
        let mut bytes = Vec::new();
        write(&t, &stats::compute(&t).workers, &c, &mut bytes).unwrap();
        let v: serde_json::Value = serde_json::from_slice(&bytes).unwrap();
        let events = v["traceEvents"].as_array().unwrap();
        let kernels: Vec<_> = events.iter().filter(|e| e["cat"] == "pass").collect();
        assert_eq!(kernels.len(), 2);
        assert_eq!(
            *kernels[0],
            serde_json::json!({"name": "density", "cat": "pass", "ph": "X", "ts": 1.5,
                "dur": 1.0, "pid": 1, "tid": 0,
                "args": {"step": 1, "first": 0, "len": 2, "worker": 0,
                         "thread": "rayon-chunks-0"}})
        );
        assert_eq!(kernels[1]["tid"], 1);
        let names: Vec<_> = events
            .iter()
            .filter(|e| e["name"] == "thread_name")
            .map(|e| {
                (
                    e["tid"].as_u64().unwrap(),
                    e["args"]["name"].as_str().unwrap(),
                )
            })
            .collect();
        assert_eq!(
            names,
            [
                (0, "worker 0 (rayon-chunks-0)"),
                (1, "worker 1 (rayon-chunks-1)"),
                (2, "serial (between passes)")
            ]
        );
        let step = events.iter().find(|e| e["ph"] == "i").unwrap();
        assert_eq!(
            (step["name"].as_str(), step["s"].as_str()),
            (Some("step 1"), Some("g"))
        );
        assert_eq!(v["otherData"]["strategy"], "rayon-chunks");
    }
}
