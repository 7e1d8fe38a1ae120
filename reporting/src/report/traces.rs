//! Trace directories (`bench-sph trace --out DIR`) that the report embeds: found under the
//! results directories and the report's own directory (up to two levels down), or named with
//! `--trace DIR`, and the report's "Traces" section ([`markdown`]).
//!
//! A directory holding `timeline.png` and `stats.csv` is a candidate; it is embedded only if
//! it validates (`check`): `stats.csv` has the trace's columns, at least one worker row and
//! a total row last whose kernel calls are the workers' sum, and only finite, non-negative
//! numbers; `timeline.png` is a PNG; `meta.json` says `"tool": "bench-sph trace"` and reads
//! as a [`TraceMeta`], the type `trace` wrote it from (a trace of an older bench-sph, which
//! lacks fields, is refused saying to run `trace` again). A `--trace DIR` that fails is an
//! error; a candidate found by scanning is skipped with a one-line warning on standard error.

use std::collections::BTreeSet;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use anyhow::{Context, bail};

use sph_harness::io::capped;
use sph_harness::output::{atomic, console, sniff};
use sph_harness::trace::files::{self, META_JSON, StatsRow, TraceMeta};
use sph_harness::trace::stats::{CSV_HEADER, idle_workers_note};

use super::table::{Column, Table};

/// The files that make a directory a trace directory.
pub const TIMELINE: &str = files::TIMELINE_PNG;
/// See [`TIMELINE`].
pub const STATS: &str = files::STATS_CSV;

/// A trace directory, read and validated.
#[derive(Debug, Clone, PartialEq)]
pub struct TraceDir {
    /// Where it is.
    pub dir: PathBuf,
    /// A title from `meta.json`: strategy, cores, chunks, N, steps.
    pub title: String,
    /// Its `stats.csv`.
    pub stats: Vec<StatsRow>,
    /// The timeline image as the report links it (relative to the report's directory).
    pub image: String,
}

impl TraceDir {
    /// The worker rows of `stats.csv`: the worker tracks the trace had.
    pub fn workers(&self) -> usize {
        self.stats.iter().filter(|r| r.kind == "worker").count()
    }

    /// The worker tracks that ran at least one kernel call.
    pub fn workers_used(&self) -> usize {
        self.stats
            .iter()
            .filter(|r| r.kind == "worker" && r.kernel_calls > 0)
            .count()
    }
}

/// What a valid trace directory holds (before its image is placed).
#[derive(Debug)]
struct Checked {
    title: String,
    stats: Vec<StatsRow>,
}

/// Whether `dir` looks like a trace (holds `timeline.png` and `stats.csv`); `check` says
/// whether it is a valid one.
pub fn is_trace_dir(dir: &Path) -> bool {
    dir.join(TIMELINE).is_file() && dir.join(STATS).is_file()
}

/// Valid trace directories under `roots` (the directories themselves and two levels below),
/// plus `explicit` ones; each once, sorted by path. An explicit directory that is not a valid
/// trace is an error; a found one is skipped with a warning on standard error.
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
        if let Err(why) = check(dir) {
            bail!("--trace '{}' is not a valid trace: {why:#}", dir.display());
        }
        found.insert(canonical(dir));
    }
    let mut candidates = BTreeSet::new();
    for root in roots {
        walk(root, 0, &mut candidates);
    }
    for dir in candidates.difference(&found.clone()) {
        match check(dir) {
            Ok(_) => {
                found.insert(dir.clone());
            }
            Err(why) => console::warn(&format!(
                "warning: skipping trace directory '{}': {why:#}",
                dir.display()
            )),
        }
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

/// Validates the trace in `dir` (see the module docs); the error says what is wrong, in a
/// phrase that follows "not a valid trace: ".
fn check(dir: &Path) -> anyhow::Result<Checked> {
    let stats = check_stats(&dir.join(STATS))?;
    if !sniff::is_png(&dir.join(TIMELINE), capped::TIMELINE_PNG)? {
        bail!("{TIMELINE} is not a PNG image");
    }
    let title = check_meta(&dir.join(META_JSON))?;
    Ok(Checked { title, stats })
}

fn check_stats(path: &Path) -> anyhow::Result<Vec<StatsRow>> {
    let text = capped::read_to_string(path, capped::TRACE_STATS_CSV)?;
    if text.lines().next() != Some(CSV_HEADER) {
        bail!("{STATS} does not have the trace's columns ({CSV_HEADER})");
    }
    let rows = csv::Reader::from_reader(text.as_bytes())
        .deserialize::<StatsRow>()
        .collect::<Result<Vec<_>, _>>()
        .with_context(|| format!("{STATS} has a malformed row"))?;
    for (i, r) in rows.iter().enumerate() {
        let line = i + 2;
        if !["worker", "pass", "total"].contains(&r.kind.as_str()) {
            bail!("{STATS} line {line}: unknown kind '{}'", r.kind);
        }
        let numbers = [
            ("busy_ms", Some(r.busy_ms)),
            ("span_ms", Some(r.span_ms)),
            ("idle_pct", Some(r.idle_pct)),
            ("imbalance", r.imbalance),
        ];
        for (column, value) in numbers {
            if let Some(v) = value.filter(|v| !(v.is_finite() && *v >= 0.0)) {
                bail!("{STATS} line {line}: {column} is {v}, not a finite non-negative number");
            }
        }
    }
    let workers: Vec<&StatsRow> = rows.iter().filter(|r| r.kind == "worker").collect();
    let Some(total) = rows.last().filter(|r| r.kind == "total") else {
        bail!("{STATS} does not end with its total row");
    };
    if workers.is_empty() || rows.iter().filter(|r| r.kind == "total").count() != 1 {
        bail!("{STATS} needs worker rows and exactly one total row");
    }
    let calls: usize = workers.iter().map(|r| r.kernel_calls).sum();
    if calls != total.kernel_calls {
        bail!(
            "{STATS}: the workers' {calls} kernel calls do not add up to the total's {}",
            total.kernel_calls
        );
    }
    Ok(rows)
}

/// The title, from a trace's `meta.json`.
fn check_meta(path: &Path) -> anyhow::Result<String> {
    let text = capped::read_to_string(path, capped::TRACE_META_JSON)
        .with_context(|| format!("no readable {META_JSON}"))?;
    let value: serde_json::Value =
        serde_json::from_str(&text).with_context(|| format!("{META_JSON} is not JSON"))?;
    if !files::is_trace_meta(&text) {
        match value.get("tool") {
            Some(tool) => bail!("{META_JSON} was written by {tool}, not \"{}\"", files::TOOL),
            None => bail!(
                "{META_JSON} is not a trace's (no \"tool\": \"{}\")",
                files::TOOL
            ),
        }
    }
    let meta: TraceMeta = serde_json::from_value(value).with_context(|| {
        format!(
            "{META_JSON} lacks the trace's configuration or totals (a trace written by an \
                 older bench-sph: run `bench-sph trace` again)"
        )
    })?;
    Ok(meta_title(&meta))
}

/// A trace's timeline to copy into the report's directory.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TimelineCopy {
    /// The trace's `timeline.png`.
    pub source: PathBuf,
    /// The copy's name in the report's directory.
    pub file: String,
}

/// Reads a valid trace directory; its timeline is linked relative to `out_dir` when it lies
/// inside it, and otherwise is to be copied ([`copy`]) into `out_dir` as
/// `[trace-]<name>-timeline.png` — with `-2`, `-3`, … when an earlier trace of this report
/// (`copied`) took that name, so two traces with the same directory name never share a copy.
/// Writes nothing: the report checks every name it will write first.
pub fn read(
    dir: &Path,
    out_dir: &Path,
    copied: &mut Vec<String>,
) -> anyhow::Result<(TraceDir, Option<TimelineCopy>)> {
    let Checked { title, stats } =
        check(dir).with_context(|| format!("'{}' is not a valid trace", dir.display()))?;
    let name = dir
        .file_name()
        .map_or_else(|| "trace".to_owned(), |n| n.to_string_lossy().into_owned());
    let out = canonical(out_dir);
    let (image, copy) = match canonical(dir).strip_prefix(&out) {
        Ok(rel) => (link(&rel.join(TIMELINE)), None),
        Err(_) => {
            let stem = if name.starts_with("trace") {
                name.clone()
            } else {
                format!("trace-{name}")
            };
            let mut file = format!("{stem}-timeline.png");
            let mut k = 1;
            while copied.contains(&file) {
                k += 1;
                file = format!("{stem}-{k}-timeline.png");
            }
            copied.push(file.clone());
            let copy = TimelineCopy {
                source: dir.join(TIMELINE),
                file: file.clone(),
            };
            (file, Some(copy))
        }
    };
    let trace = TraceDir {
        dir: dir.to_path_buf(),
        title,
        stats,
        image,
    };
    Ok((trace, copy))
}

/// Copies a timeline to `dest` (whole or not at all).
pub fn copy(copy: &TimelineCopy, dest: &Path) -> anyhow::Result<()> {
    let bytes = capped::read(&copy.source, capped::TIMELINE_PNG)?;
    atomic::write(dest, &bytes)
}

/// A relative path with `/` separators, for Markdown.
fn link(p: &Path) -> String {
    p.components()
        .map(|c| c.as_os_str().to_string_lossy().into_owned())
        .collect::<Vec<_>>()
        .join("/")
}

fn meta_title(meta: &TraceMeta) -> String {
    let m = &meta.config;
    let chunks = m
        .chunks
        .map_or_else(String::new, |k| format!(", {k} chunks"));
    let extra = format!(" ({}, {})", m.preset.as_str(), m.neighbors.as_str());
    format!(
        "{}, {} {}{chunks}, N = {}, {} steps{extra}",
        m.strategy,
        m.cores,
        if m.cores == 1 { "core" } else { "cores" },
        m.n,
        m.steps
    )
}

/// `x` to three significant digits (`1.12`, `0.0396`, `59.4`, `1450`); counts of kernel
/// calls are printed whole, being exact.
fn sig3(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    let scale = 10f64.powi(2 - x.abs().log10().floor() as i32);
    let rounded = (x * scale).round() / scale;
    let decimals = (2 - rounded.abs().log10().floor() as i32).max(0) as usize;
    format!("{rounded:.decimals$}")
}

/// The report's "Traces" section (empty without traces): per trace its title, timeline,
/// per-pass table and totals, then either the plain fact that only some workers ran kernels
/// or a sentence on what the timeline shows. Every measured number has at most three
/// significant digits.
pub fn markdown(traces: &[TraceDir]) -> String {
    let mut md = String::new();
    if traces.is_empty() {
        return md;
    }
    let _ = writeln!(
        md,
        "## Traces\n\nTimelines from `bench-sph trace` (one bar per kernel call; white where a \
         worker is idle).\n"
    );
    for t in traces {
        let _ = writeln!(md, "### {}\n", t.title);
        let _ = writeln!(md, "![timeline: {}]({})\n", t.title, t.image);
        let mut table = Table::new([
            Column::left("pass"),
            Column::right("kernel calls"),
            Column::right("busy (ms)"),
            Column::right("span (ms)"),
            Column::right("idle %"),
            Column::right("imbalance"),
        ]);
        for r in t.stats.iter().filter(|r| r.kind == "pass") {
            table.row([
                r.name.clone(),
                r.kernel_calls.to_string(),
                sig3(r.busy_ms),
                sig3(r.span_ms),
                sig3(r.idle_pct),
                r.imbalance.map_or_else(|| "—".to_owned(), sig3),
            ]);
        }
        let _ = write!(md, "{table}");
        if let Some(total) = t.stats.iter().find(|r| r.kind == "total") {
            let (used, workers) = (t.workers_used(), t.workers());
            let _ = writeln!(
                md,
                "\nIn total {} kernel calls on {used} of {workers} {}; the workers were idle \
                 {} % of the {} ms loop.",
                total.kernel_calls,
                if workers == 1 { "worker" } else { "workers" },
                sig3(total.idle_pct),
                sig3(total.span_ms)
            );
            let reading = match idle_workers_note(used, workers) {
                Some(note) => capitalised(&note) + ".",
                None => reading(total),
            };
            let _ = writeln!(md, "\n{reading}");
        }
        md.push('\n');
    }
    md
}

fn capitalised(s: &str) -> String {
    let mut chars = s.chars();
    chars.next().map_or_else(String::new, |c| {
        c.to_uppercase().collect::<String>() + chars.as_str()
    })
}

/// One sentence on what a timeline on every worker shows: how much work a kernel call
/// carries and how much of the loop the workers spend outside kernel calls.
fn reading(total: &StatsRow) -> String {
    let per_call_us = 1000.0 * total.busy_ms / total.kernel_calls.max(1) as f64;
    let grain = format!(
        "a kernel call carries {} µs of work on average",
        sig3(per_call_us)
    );
    if total.idle_pct > 50.0 {
        format!(
            "What it shows: {grain}, and the workers spend most of the loop ({} %) outside \
             kernel calls: scheduling the calls, waiting at the end of each pass and for the \
             serial work between passes.",
            sig3(total.idle_pct)
        )
    } else {
        format!(
            "What it shows: {grain}, and the workers stay busy {} % of the loop; the gaps are \
             the waits at the end of each pass and the serial work between passes.",
            sig3(100.0 - total.idle_pct)
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use sph_harness::output::sniff::PNG_SIGNATURE;

    const STATS_TEXT: &str = "kind,name,threads,kernel_calls,busy_ms,span_ms,idle_pct,imbalance\n\
         worker,0,1,3,0.5,1.0,50.0,\nworker,1,1,2,0.3,1.0,70.0,\n\
         pass,density,,2,0.4,0.3,33.3,1.5\ntotal,all,2,5,0.8,1.0,60.0,\n";
    /// A trace's `meta.json`, as `trace` writes it.
    fn meta() -> TraceMeta {
        TraceMeta {
            tool: Some(files::TOOL.to_owned()),
            config: sph_harness::trace::TraceConfig {
                strategy: "rayon-chunks".to_owned(),
                cores: 2,
                chunks: Some(45),
                n: 1000,
                steps: 3,
                preset: sph_solver::models::Preset::Seed,
                neighbors: sph_solver::sph::neighbors::NeighborMode::AllPairs,
                seed: Some(2019),
                init: None,
            },
            warmup_steps: 5,
            wall_s: 0.1,
            cpu_s: 0.2,
            kernel_calls: 5,
            worker_threads: 2,
            workers_used: 2,
            checksum: "00000000000000aa".to_owned(),
            timeline_steps: [1, 3],
            simd: sph_solver::simd::SimdPath::Portable,
            pin: sph_harness::topology::Pin::None,
        }
    }

    fn fake_trace(dir: &Path) {
        std::fs::create_dir_all(dir).unwrap();
        std::fs::write(dir.join(TIMELINE), PNG_SIGNATURE).unwrap();
        std::fs::write(dir.join(STATS), STATS_TEXT).unwrap();
        let text = serde_json::to_string_pretty(&meta()).unwrap();
        std::fs::write(dir.join(META_JSON), text).unwrap();
    }

    #[test]
    fn a_trace_s_meta_json_reads_back_as_written_and_an_older_one_is_refused_saying_so() {
        let text = serde_json::to_string_pretty(&meta()).unwrap();
        assert_eq!(serde_json::from_str::<TraceMeta>(&text).unwrap(), meta());
        let tmp = tempfile::tempdir().unwrap();
        fake_trace(tmp.path());
        assert_eq!(
            check(tmp.path()).unwrap().title,
            "rayon-chunks, 2 cores, 45 chunks, N = 1000, 3 steps (seed, all-pairs)"
        );
        // Written before the totals were: the configuration alone.
        let older = r#"{"tool":"bench-sph trace","strategy":"rayon-chunks","cores":2,"chunks":45,"n":1000,"steps":3,"kernel_calls":5,"timeline_steps":[1,3]}"#;
        std::fs::write(tmp.path().join(META_JSON), older).unwrap();
        let why = format!("{:#}", check(tmp.path()).unwrap_err());
        assert!(why.contains("an older bench-sph"), "{why}");
    }

    /// Why `check` refuses `dir` after `spoil` has changed one of its files.
    fn refusal(spoil: impl Fn(&Path)) -> String {
        let tmp = tempfile::tempdir().unwrap();
        fake_trace(tmp.path());
        spoil(tmp.path());
        format!("{:#}", check(tmp.path()).unwrap_err())
    }

    #[test]
    fn two_traces_with_the_same_directory_name_get_copies_of_their_own() {
        let out = tempfile::tempdir().unwrap();
        let mut copied = Vec::new();
        let mut names = Vec::new();
        for parent in ["a", "b"] {
            let dir = tempfile::tempdir().unwrap();
            let t = dir.path().join(parent).join("tr");
            fake_trace(&t);
            names.push(read(&t, out.path(), &mut copied).unwrap().0.image);
        }
        assert_eq!(names, ["trace-tr-timeline.png", "trace-tr-2-timeline.png"]);
    }

    #[test]
    fn trace_directories_are_found_below_a_root_and_linked_relative_to_the_report() {
        let root = tempfile::tempdir().unwrap();
        fake_trace(&root.path().join("traces/trace-a"));
        std::fs::create_dir_all(root.path().join("empty")).unwrap();
        let found = find(&[root.path().to_path_buf()], &[]).unwrap();
        assert_eq!(found.len(), 1);
        let (t, copy) = read(&found[0], root.path(), &mut Vec::new()).unwrap();
        assert_eq!(t.image, "traces/trace-a/timeline.png");
        assert_eq!(
            copy, None,
            "a trace inside the report is linked, not copied"
        );
        assert_eq!(
            t.title,
            "rayon-chunks, 2 cores, 45 chunks, N = 1000, 3 steps (seed, all-pairs)"
        );
        assert_eq!(t.stats.len(), 4);
        assert_eq!(t.stats[2].imbalance, Some(1.5));
        assert_eq!((t.workers_used(), t.workers()), (2, 2));
    }

    #[test]
    fn a_trace_outside_the_report_is_copied_in_and_a_non_trace_is_refused() {
        let a = tempfile::tempdir().unwrap();
        let out = tempfile::tempdir().unwrap();
        fake_trace(&a.path().join("t1"));
        let (t, copy) = read(&a.path().join("t1"), out.path(), &mut Vec::new()).unwrap();
        assert_eq!(t.image, "trace-t1-timeline.png");
        let copy = copy.unwrap();
        assert!(
            !out.path().join("trace-t1-timeline.png").exists(),
            "read writes nothing"
        );
        super::copy(&copy, &out.path().join(&copy.file)).unwrap();
        assert!(out.path().join("trace-t1-timeline.png").is_file());
        let err = find(&[], &[a.path().to_path_buf()]).unwrap_err();
        assert!(
            err.to_string().contains("is not a trace directory"),
            "{err}"
        );
    }

    #[test]
    fn a_junk_trace_found_by_scanning_is_skipped_but_one_named_with_trace_is_an_error() {
        let root = tempfile::tempdir().unwrap();
        let junk = root.path().join("junk");
        fake_trace(&junk);
        std::fs::write(junk.join(TIMELINE), b"GIF89a").unwrap();
        fake_trace(&root.path().join("good"));
        let found = find(&[root.path().to_path_buf()], &[]).unwrap();
        assert_eq!(found, [canonical(&root.path().join("good"))]);
        let err = find(&[], &[junk]).unwrap_err().to_string();
        assert!(
            err.ends_with("is not a valid trace: timeline.png is not a PNG image"),
            "{err}"
        );
    }

    #[test]
    fn stats_must_have_the_columns_a_last_total_row_and_finite_non_negative_numbers() {
        let no_total = refusal(|d| {
            let text = STATS_TEXT.replace("total,all,2,5,0.8,1.0,60.0,\n", "");
            std::fs::write(d.join(STATS), text).unwrap();
        });
        assert_eq!(no_total, "stats.csv does not end with its total row");
        let negative = refusal(|d| {
            std::fs::write(
                d.join(STATS),
                STATS_TEXT.replace("0.5,1.0,50.0", "-0.5,1.0,50.0"),
            )
            .unwrap();
        });
        assert_eq!(
            negative,
            "stats.csv line 2: busy_ms is -0.5, not a finite non-negative number"
        );
        let nan = refusal(|d| {
            std::fs::write(d.join(STATS), STATS_TEXT.replace("1.5", "NaN")).unwrap();
        });
        assert!(nan.contains("imbalance is NaN"), "{nan}");
        let columns = refusal(|d| std::fs::write(d.join(STATS), "a,b\n1,2\n").unwrap());
        assert!(columns.starts_with("stats.csv does not have the trace's columns"));
        let sums = refusal(|d| {
            std::fs::write(
                d.join(STATS),
                STATS_TEXT.replace("total,all,2,5", "total,all,2,6"),
            )
            .unwrap();
        });
        assert!(sums.contains("do not add up"), "{sums}");
    }

    #[test]
    fn meta_must_be_a_trace_s_and_an_older_trace_without_tool_is_accepted() {
        let sweep = refusal(|d| {
            std::fs::write(d.join(META_JSON), r#"{"tool":"bench-sph sweep"}"#).unwrap();
        });
        assert_eq!(
            sweep,
            "meta.json was written by \"bench-sph sweep\", not \"bench-sph trace\""
        );
        let missing = refusal(|d| std::fs::remove_file(d.join(META_JSON)).unwrap());
        assert!(missing.starts_with("no readable meta.json"), "{missing}");
        let tmp = tempfile::tempdir().unwrap();
        fake_trace(tmp.path());
        // Written before the `tool` field (and the totals after it) existed: recognised as a
        // trace, refused as an older one.
        let older = r#"{"strategy":"rayon-chunks","cores":2,"chunks":45,"n":1000,"steps":3,"kernel_calls":5,"timeline_steps":[1,3]}"#;
        std::fs::write(tmp.path().join(META_JSON), older).unwrap();
        let why = format!("{:#}", check(tmp.path()).unwrap_err());
        assert!(why.contains("an older bench-sph"), "{why}");
    }

    #[test]
    fn numbers_have_at_most_three_significant_digits() {
        let cases = [
            (1.118, "1.12"),
            (0.039645, "0.0396"),
            (59.38, "59.4"),
            (1453.4, "1450"),
            (9.996, "10.0"),
            (2.0, "2.00"),
            (0.0, "0"),
        ];
        for (x, shown) in cases {
            assert_eq!(sig3(x), shown, "{x}");
        }
    }

    #[test]
    fn a_trace_on_one_of_two_workers_says_so_instead_of_explaining_the_idle_share() {
        let tmp = tempfile::tempdir().unwrap();
        fake_trace(tmp.path());
        let (mut t, _) = read(tmp.path(), tmp.path(), &mut Vec::new()).unwrap();
        t.stats[0].kernel_calls = 5;
        t.stats[1].kernel_calls = 0;
        let md = markdown(&[t]);
        assert!(
            md.contains("In total 5 kernel calls on 1 of 2 workers; the workers were idle 60.0 % of the 1.00 ms loop."),
            "{md}"
        );
        assert!(
            md.contains("\nOnly 1 of 2 workers ran kernels in the recorded steps; the timeline does not show parallel execution.\n"),
            "{md}"
        );
        assert!(!md.contains("What it shows"), "{md}");
        assert!(
            md.contains("| density | 2 | 0.400 | 0.300 | 33.3 | 1.50 |"),
            "{md}"
        );
    }
}
