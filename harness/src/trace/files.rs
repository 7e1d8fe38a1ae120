//! The schema of a trace directory: its files' names, its `meta.json` ([`TraceMeta`]) and the
//! rows of its `stats.csv` ([`StatsRow`]), which `trace` writes and `report` reads through
//! these same types. Which files `trace --out` may replace is the directory's record
//! ([`crate::output::record`]).

use serde::{Deserialize, Serialize};

use crate::topology::Pin;
use sph_solver::models::Preset;
use sph_solver::simd::SimdPath;
use sph_solver::sph::neighbors::NeighborMode;

/// The `tool` field of a trace's `meta.json`.
pub const TOOL: &str = "bench-sph trace";
/// Chrome trace events.
pub const TRACE_JSON: &str = "trace.json";
/// The Gantt chart.
pub const TIMELINE_PNG: &str = "timeline.png";
/// Per worker, per pass and total statistics.
pub const STATS_CSV: &str = "stats.csv";
/// The configuration and totals.
pub const META_JSON: &str = "meta.json";

/// What was traced: shown in titles and written to `trace.json`'s `otherData` and `meta.json`.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct TraceConfig {
    /// The strategy's name.
    pub strategy: String,
    /// Worker threads (1 for `seq`).
    pub cores: usize,
    /// Requested chunks per pass, for strategies that use chunks.
    pub chunks: Option<usize>,
    /// Particles.
    pub n: usize,
    /// Steps traced.
    pub steps: usize,
    /// Constants.
    pub preset: Preset,
    /// Neighbour search.
    pub neighbors: NeighborMode,
    /// Seed of the initial jitter (none with an init file).
    pub seed: Option<u64>,
    /// The init file the state came from, if any.
    pub init: Option<String>,
}

impl TraceConfig {
    /// One line: `rayon-chunks, 2 cores, 45 chunks, N = 1000 (seed, all-pairs)`.
    pub fn title(&self) -> String {
        let cores = if self.cores == 1 { "core" } else { "cores" };
        let chunks = self
            .chunks
            .map_or_else(String::new, |c| format!(", {c} chunks"));
        format!(
            "{}, {} {cores}{chunks}, N = {} ({}, {})",
            self.strategy,
            self.cores,
            self.n,
            self.preset.as_str(),
            self.neighbors.as_str()
        )
    }
}

/// A trace's `meta.json`: the tool, the configuration, the run's timing and its totals.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TraceMeta {
    /// [`TOOL`]. Traces written before the field existed lack it, and with it the totals
    /// that came later: [`is_trace_meta`] still recognises them, and the report refuses them
    /// saying to run `trace` again.
    pub tool: Option<String>,
    /// What was traced.
    #[serde(flatten)]
    pub config: TraceConfig,
    /// Untimed, unrecorded steps before the recorded ones.
    pub warmup_steps: usize,
    /// Wall time of the recorded steps, s.
    pub wall_s: f64,
    /// CPU time of the recorded steps, s.
    pub cpu_s: f64,
    /// Kernel calls recorded.
    pub kernel_calls: usize,
    /// Distinct worker threads.
    pub worker_threads: usize,
    /// Worker tracks that ran at least one kernel call.
    pub workers_used: usize,
    /// The final state's checksum.
    pub checksum: String,
    /// The first and last step drawn in `timeline.png`.
    pub timeline_steps: [usize; 2],
    /// The SIMD path the run's vector code ran on.
    pub simd: SimdPath,
    /// Where the threads were placed.
    pub pin: Pin,
}

/// One row of a trace's `stats.csv` (header [`crate::trace::stats::CSV_HEADER`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StatsRow {
    /// `worker`, `pass` or `total`.
    pub kind: String,
    /// Worker index, pass name or `all`.
    pub name: String,
    /// OS threads (workers and total only).
    pub threads: Option<usize>,
    /// Kernel calls (tasks).
    pub kernel_calls: usize,
    /// Milliseconds inside kernel calls.
    pub busy_ms: f64,
    /// Milliseconds of the span (the loop, or the pass summed over steps).
    pub span_ms: f64,
    /// Percent idle.
    pub idle_pct: f64,
    /// Busiest worker over the mean worker, per pass.
    pub imbalance: Option<f64>,
}

/// Whether a `meta.json` text is a trace's: `"tool": "bench-sph trace"`, or, written before
/// that field existed, no `tool` but the trace's own `timeline_steps` and `kernel_calls` (so
/// that such a trace is named as an older trace's, not as another tool's file).
pub fn is_trace_meta(text: &str) -> bool {
    let Ok(serde_json::Value::Object(meta)) = serde_json::from_str(text) else {
        return false;
    };
    match meta.get("tool") {
        Some(tool) => tool == TOOL,
        None => meta.contains_key("timeline_steps") && meta.contains_key("kernel_calls"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_sweep_s_meta_json_is_not_trace_s_but_an_older_trace_s_is() {
        assert!(is_trace_meta(
            r#"{"tool":"bench-sph trace","strategy":"seq"}"#
        ));
        assert!(!is_trace_meta(r#"{"tool":"bench-sph sweep","params":{}}"#));
        assert!(is_trace_meta(
            r#"{"strategy":"seq","kernel_calls":3,"timeline_steps":[1,3]}"#
        ));
        assert!(!is_trace_meta(r#"{"strategy":"seq"}"#));
        assert!(!is_trace_meta("not json"));
    }
}
