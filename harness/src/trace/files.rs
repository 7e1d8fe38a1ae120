//! The files of a trace directory, and what `report` accepts as a trace's `meta.json`. Which
//! files `trace --out` may replace is the directory's record ([`crate::output::record`]).

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

/// Whether a `meta.json` text is a trace's: `"tool": "bench-sph trace"`, or, written before
/// that field existed, no `tool` but the trace's own `timeline_steps` and `kernel_calls`.
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
