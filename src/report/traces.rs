//! Trace directories (`bench-sph trace --out DIR`) that the report embeds: found under the
//! results directories and the report's own directory (up to two levels down), or named with
//! `--trace DIR`. A trace directory is one holding both `timeline.png` and `stats.csv`; its
//! `meta.json`, when present, gives the title.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use anyhow::{Context, bail};
use serde::Deserialize;

/// The files that make a directory a trace directory.
pub const TIMELINE: &str = "timeline.png";
/// See [`TIMELINE`].
pub const STATS: &str = "stats.csv";

/// One row of a trace's `stats.csv`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
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

/// A trace directory, read.
#[derive(Debug, Clone, PartialEq)]
pub struct TraceDir {
    /// Where it is.
    pub dir: PathBuf,
    /// A title: from `meta.json` (strategy, cores, chunks, N, steps) or the directory name.
    pub title: String,
    /// Its `stats.csv`.
    pub stats: Vec<StatsRow>,
    /// The timeline image as the report links it (relative to the report's directory).
    pub image: String,
}

#[derive(Debug, Deserialize)]
struct TraceMeta {
    strategy: String,
    cores: usize,
    chunks: Option<usize>,
    n: usize,
    steps: usize,
    preset: Option<String>,
    neighbors: Option<String>,
}

/// Whether `dir` holds a trace.
pub fn is_trace_dir(dir: &Path) -> bool {
    dir.join(TIMELINE).is_file() && dir.join(STATS).is_file()
}

/// Trace directories under `roots` (the directories themselves and two levels below), plus
/// `explicit` ones (an error if one is not a trace directory); each once, sorted by path.
pub fn find(roots: &[PathBuf], explicit: &[PathBuf]) -> anyhow::Result<Vec<PathBuf>> {
    let mut found: BTreeSet<PathBuf> = BTreeSet::new();
    for dir in explicit {
        if !is_trace_dir(dir) {
            bail!(
                "--trace '{}' is not a trace directory (it needs {TIMELINE} and {STATS}, as \
                 written by `bench-sph trace --out DIR`)",
                dir.display()
            );
        }
        found.insert(canonical(dir));
    }
    for root in roots {
        walk(root, 0, &mut found);
    }
    Ok(found.into_iter().collect())
}

fn canonical(p: &Path) -> PathBuf {
    std::fs::canonicalize(p).unwrap_or_else(|_| p.to_path_buf())
}

fn walk(dir: &Path, depth: usize, found: &mut BTreeSet<PathBuf>) {
    if is_trace_dir(dir) {
        found.insert(canonical(dir));
    }
    if depth >= 2 {
        return;
    }
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    let mut subdirs: Vec<PathBuf> = entries
        .filter_map(Result::ok)
        .map(|e| e.path())
        .filter(|p| p.is_dir())
        .collect();
    subdirs.sort();
    for d in subdirs {
        walk(&d, depth + 1, found);
    }
}

/// Reads a trace directory; its timeline is linked relative to `out_dir` when it lies inside
/// it, and otherwise copied into `out_dir` as `[trace-]<name>-timeline.png`.
pub fn read(dir: &Path, out_dir: &Path) -> anyhow::Result<TraceDir> {
    let stats_path = dir.join(STATS);
    let mut reader = csv::Reader::from_path(&stats_path)
        .with_context(|| format!("cannot read '{}'", stats_path.display()))?;
    let stats = reader
        .deserialize::<StatsRow>()
        .collect::<Result<Vec<_>, _>>()
        .with_context(|| {
            format!(
                "'{}' is not a bench-sph trace's stats.csv",
                stats_path.display()
            )
        })?;
    let name = dir
        .file_name()
        .map_or_else(|| "trace".to_owned(), |n| n.to_string_lossy().into_owned());
    let title = std::fs::read_to_string(dir.join("meta.json"))
        .ok()
        .and_then(|t| serde_json::from_str::<TraceMeta>(&t).ok())
        .map_or_else(|| name.clone(), |m| meta_title(&m));
    let out = canonical(out_dir);
    let image = match canonical(dir).strip_prefix(&out) {
        Ok(rel) => link(&rel.join(TIMELINE)),
        Err(_) => {
            let file = if name.starts_with("trace") {
                format!("{name}-timeline.png")
            } else {
                format!("trace-{name}-timeline.png")
            };
            std::fs::copy(dir.join(TIMELINE), out_dir.join(&file)).with_context(|| {
                format!(
                    "cannot copy '{}' into '{}'",
                    dir.join(TIMELINE).display(),
                    out_dir.display()
                )
            })?;
            file
        }
    };
    Ok(TraceDir {
        dir: dir.to_path_buf(),
        title,
        stats,
        image,
    })
}

/// A relative path with `/` separators, for Markdown.
fn link(p: &Path) -> String {
    p.components()
        .map(|c| c.as_os_str().to_string_lossy().into_owned())
        .collect::<Vec<_>>()
        .join("/")
}

fn meta_title(m: &TraceMeta) -> String {
    let chunks = m
        .chunks
        .map_or_else(String::new, |k| format!(", {k} chunks"));
    let extra = match (&m.preset, &m.neighbors) {
        (Some(p), Some(nb)) => format!(" ({p}, {nb})"),
        _ => String::new(),
    };
    format!(
        "{}, {} {}{chunks}, N = {}, {} steps{extra}",
        m.strategy,
        m.cores,
        if m.cores == 1 { "core" } else { "cores" },
        m.n,
        m.steps
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fake_trace(dir: &Path) {
        std::fs::create_dir_all(dir).unwrap();
        std::fs::write(dir.join(TIMELINE), b"png").unwrap();
        std::fs::write(
            dir.join(STATS),
            "kind,name,threads,kernel_calls,busy_ms,span_ms,idle_pct,imbalance\n\
             worker,0,1,3,0.5,1.0,50.0,\npass,density,,2,0.4,0.3,33.3,1.5\ntotal,all,2,5,0.8,1.0,60.0,\n",
        )
        .unwrap();
        std::fs::write(
            dir.join("meta.json"),
            r#"{"strategy":"rayon-chunks","cores":2,"chunks":45,"n":1000,"steps":3,"preset":"seed","neighbors":"all-pairs","seed":2019,"wall_s":0.1}"#,
        )
        .unwrap();
    }

    #[test]
    fn trace_directories_are_found_below_a_root_and_linked_relative_to_the_report() {
        let root = tempfile::tempdir().unwrap();
        fake_trace(&root.path().join("traces/trace-a"));
        std::fs::create_dir_all(root.path().join("empty")).unwrap();
        let found = find(&[root.path().to_path_buf()], &[]).unwrap();
        assert_eq!(found.len(), 1);
        let t = read(&found[0], root.path()).unwrap();
        assert_eq!(t.image, "traces/trace-a/timeline.png");
        assert_eq!(
            t.title,
            "rayon-chunks, 2 cores, 45 chunks, N = 1000, 3 steps (seed, all-pairs)"
        );
        assert_eq!(t.stats.len(), 3);
        assert_eq!(t.stats[1].imbalance, Some(1.5));
    }

    #[test]
    fn a_trace_outside_the_report_is_copied_in_and_a_non_trace_is_refused() {
        let a = tempfile::tempdir().unwrap();
        let out = tempfile::tempdir().unwrap();
        fake_trace(&a.path().join("t1"));
        let t = read(&a.path().join("t1"), out.path()).unwrap();
        assert_eq!(t.image, "trace-t1-timeline.png");
        assert!(out.path().join("trace-t1-timeline.png").is_file());
        let err = find(&[], &[a.path().to_path_buf()]).unwrap_err();
        assert!(
            err.to_string().contains("is not a trace directory"),
            "{err}"
        );
    }
}
