//! The files of a trace directory, and how `trace` recognises its own: what `trace --out`
//! may replace, and what `report` accepts as a trace.

use crate::output::sniff::{PNG_SIGNATURE, starts_with};
use std::path::Path;

use super::stats::CSV_HEADER;

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

/// How `trace.json` starts.
const TRACE_JSON_START: &[u8] = b"{\"traceEvents\":";

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

/// Whether `path` is a file an earlier `trace` wrote, judged by name and content: a
/// `trace.json` of Chrome trace events, a PNG `timeline.png`, a `stats.csv` with the trace's
/// header, a trace's `meta.json` ([`is_trace_meta`]). Anything else is not trace's to replace.
pub fn owns(path: &Path) -> bool {
    if !path.is_file() {
        return false;
    }
    match path.file_name().and_then(|n| n.to_str()) {
        Some(TRACE_JSON) => starts_with(path, TRACE_JSON_START),
        Some(TIMELINE_PNG) => starts_with(path, &PNG_SIGNATURE),
        Some(STATS_CSV) => starts_with(path, format!("{CSV_HEADER}\n").as_bytes()),
        Some(META_JSON) => std::fs::read_to_string(path).is_ok_and(|t| is_trace_meta(&t)),
        _ => false,
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

    #[test]
    fn files_are_owned_by_name_and_content() {
        let tmp = tempfile::tempdir().unwrap();
        let p = |name: &str| tmp.path().join(name);
        std::fs::write(p(TIMELINE_PNG), b"not a png").unwrap();
        std::fs::write(p(STATS_CSV), format!("{CSV_HEADER}\ntotal,all\n")).unwrap();
        std::fs::write(p(TRACE_JSON), b"{\"traceEvents\":[]}").unwrap();
        std::fs::write(p("notes.txt"), b"").unwrap();
        assert!(!owns(&p(TIMELINE_PNG)));
        assert!(owns(&p(STATS_CSV)) && owns(&p(TRACE_JSON)));
        assert!(!owns(&p("notes.txt")) && !owns(&p(META_JSON)));
        std::fs::write(p(TIMELINE_PNG), PNG_SIGNATURE).unwrap();
        assert!(owns(&p(TIMELINE_PNG)));
    }
}
