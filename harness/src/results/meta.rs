//! `meta.json`: what was run, on what, with what, and when.
//!
//! Top level: the tool's version and git commit, the compiler, the machine, the first
//! session's command line and start time, the last end time, the sweep's `status`
//! (`running`, `complete` or `interrupted`) and every parameter (`params`, which `--resume`
//! reads back). `sessions` lists every invocation (the first and each `--resume`) with its own
//! command line, times, machine and number of cells run.

use std::path::Path;

use anyhow::Context;
use serde::{Deserialize, Serialize};

use super::params::SweepParams;
use super::shard::Shard;
use super::stats::CONFIDENCE;
use crate::io::capped;
use crate::topology::Topology;

/// The version of bench-sph that wrote the file.
pub const VERSION: &str = env!("CARGO_PKG_VERSION");
/// The git commit bench-sph was built from (`-dirty` with local changes), or `unknown`.
pub const GIT_COMMIT: &str = env!("BENCH_SPH_GIT_COMMIT");
/// `rustc --version` of the compiler that built bench-sph.
pub const RUSTC: &str = env!("BENCH_SPH_RUSTC");

/// The state of a sweep as a whole.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum SweepStatus {
    /// A session is running it (or was killed without a chance to say otherwise).
    Running,
    /// Every planned cell has a summary row.
    Complete,
    /// Stopped by Ctrl-C, SIGTERM, SIGHUP or a closed standard output; `--resume` continues it.
    Interrupted,
    /// A merge of shards with cells missing (`bench-sph merge --allow-partial`): resume or run
    /// the missing shards and merge again.
    Partial,
}

impl SweepStatus {
    /// The word written in `meta.json`.
    pub fn as_str(self) -> &'static str {
        match self {
            SweepStatus::Running => "running",
            SweepStatus::Complete => "complete",
            SweepStatus::Interrupted => "interrupted",
            SweepStatus::Partial => "partial",
        }
    }
}

/// The `tool` a sweep (and a merge of shards) writes in `meta.json`.
pub const SWEEP_TOOL: &str = "bench-sph sweep";

/// The machine a session ran on.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Machine {
    /// The CPU's model name from /proc/cpuinfo, or `unknown`.
    pub cpu_model: String,
    /// Hardware threads available to the process.
    pub hardware_threads: usize,
    /// The operating system's name (PRETTY_NAME of /etc/os-release), or the OS family.
    pub os: String,
    /// The kernel release (/proc/sys/kernel/osrelease), or `unknown`.
    pub kernel: String,
    /// The CPU architecture bench-sph was built for.
    pub arch: String,
    /// Cores, SMT siblings, sockets, caches and frequency policy of the CPUs the process
    /// may use (unknown, `logical_cpus` 0, in files written before it was recorded).
    #[serde(default)]
    pub topology: Topology,
}

impl Machine {
    /// Reads the machine's description (never fails: unknown parts say `unknown`).
    pub fn detect() -> Machine {
        let read = |path: &str| std::fs::read_to_string(path).unwrap_or_default();
        let kernel = read("/proc/sys/kernel/osrelease").trim().to_owned();
        Machine {
            cpu_model: cpu_model(&read("/proc/cpuinfo")).unwrap_or_else(|| "unknown".to_owned()),
            hardware_threads: std::thread::available_parallelism().map_or(1, |n| n.get()),
            os: pretty_name(&read("/etc/os-release"))
                .unwrap_or_else(|| std::env::consts::OS.to_owned()),
            kernel: if kernel.is_empty() {
                "unknown".to_owned()
            } else {
                kernel
            },
            arch: std::env::consts::ARCH.to_owned(),
            topology: Topology::detect(),
        }
    }
}

impl Machine {
    /// Whether timings from `self` and `other` may be pooled as one machine's: the same CPU
    /// model and the same number of hardware threads. Anything else makes two sweeps a
    /// comparison between machines, not one study.
    pub fn same_hardware(&self, other: &Machine) -> bool {
        self.cpu_model == other.cpu_model && self.hardware_threads == other.hardware_threads
    }

    /// How reports and messages name the machine, e.g. `Intel(R) Xeon(R) Processor, 2
    /// hardware threads`.
    pub fn label(&self) -> String {
        format!(
            "{}, {}",
            self.cpu_model,
            crate::output::console::plural(
                self.hardware_threads,
                "hardware thread",
                "hardware threads"
            )
        )
    }
}

/// The first `model name` (x86) or, failing that, `Hardware`/`Processor`/`cpu model` value.
fn cpu_model(cpuinfo: &str) -> Option<String> {
    ["model name", "Hardware", "Processor", "cpu model"]
        .iter()
        .find_map(|key| {
            cpuinfo.lines().find_map(|line| {
                let (k, v) = line.split_once(':')?;
                (k.trim() == *key && !v.trim().is_empty()).then(|| v.trim().to_owned())
            })
        })
}

/// PRETTY_NAME from os-release text, unquoted.
fn pretty_name(os_release: &str) -> Option<String> {
    os_release.lines().find_map(|line| {
        let v = line.strip_prefix("PRETTY_NAME=")?;
        Some(v.trim().trim_matches('"').to_owned())
    })
}

/// One invocation of `bench-sph sweep` on a results directory.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Session {
    /// The command line, program name first.
    pub command_line: Vec<String>,
    /// When it started, UTC, RFC 3339.
    pub started_utc: String,
    /// When it ended, UTC, RFC 3339 (`null` while running or if it was killed).
    pub finished_utc: Option<String>,
    /// How it ended.
    pub status: SweepStatus,
    /// Cells it measured.
    pub cells_run: usize,
    /// bench-sph version.
    pub version: String,
    /// bench-sph git commit.
    pub git_commit: String,
    /// The machine.
    pub machine: Machine,
    /// Hardware threads' worth of CPU other work was using just before the session started
    /// (`null` where unknown; see [`crate::contention`]).
    #[serde(default)]
    pub busy_threads_at_start: Option<f64>,
}

/// How the runs were ordered and how the summary's intervals and `contended` flags were
/// computed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Statistics {
    /// How the intervals were computed: `student-t` ([`crate::results::intervals`]: the
    /// time's on the logarithms of the runs, the speedup's on the logarithms of the per-round
    /// ratios, both exponentiated); absent
    /// in sweeps written before rounds, whose intervals came from the percentile bootstrap.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub intervals: Option<String>,
    /// The intervals' confidence level.
    pub confidence: f64,
    /// The fewest rounds that give an interval.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub min_rounds: Option<usize>,
    /// The seed of the rounds' shuffles (the sweep's `seed`; see
    /// [`crate::sweep::schedule::round_seed`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shuffle_seed: Option<u64>,
    /// Bootstrap resamples per interval (sweeps written before rounds).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bootstrap_resamples: Option<usize>,
    /// The seed of the bootstrap's random streams (sweeps written before rounds).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bootstrap_seed: Option<u64>,
    /// Share of the machine's capacity other work may take before a window is contended.
    pub contended_share: f64,
    /// The shortest contention window, wall seconds ([`crate::sweep::windows`]); absent in
    /// sweeps written before windows, which judged each trial alone.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub contention_window_s: Option<f64>,
}

impl Statistics {
    /// This version's settings for a sweep with `seed`.
    pub fn current(seed: u64) -> Statistics {
        Statistics {
            intervals: Some("student-t".to_owned()),
            confidence: CONFIDENCE,
            min_rounds: Some(crate::results::intervals::MIN_ROUNDS),
            shuffle_seed: Some(seed),
            bootstrap_resamples: None,
            bootstrap_seed: None,
            contended_share: crate::contention::CONTENDED_SHARE,
            contention_window_s: Some(crate::contention::WINDOW_S),
        }
    }

    /// Whether the sweep ran before rounds: cells back to back, bootstrap intervals.
    pub fn before_rounds(&self) -> bool {
        self.intervals.is_none()
    }
}

impl Session {
    /// A session starting now.
    pub fn start(command_line: Vec<String>, machine: Machine) -> Session {
        Session {
            command_line,
            started_utc: now_utc(),
            finished_utc: None,
            status: SweepStatus::Running,
            cells_run: 0,
            version: VERSION.to_owned(),
            git_commit: GIT_COMMIT.to_owned(),
            machine,
            busy_threads_at_start: None,
        }
    }
}

/// The contents of `meta.json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Meta {
    /// Always `bench-sph sweep`.
    pub tool: String,
    /// bench-sph version of the first session.
    pub version: String,
    /// bench-sph git commit of the first session, or `unknown`.
    pub git_commit: String,
    /// Whether that build had uncommitted changes to tracked files (then the commit does not
    /// describe the code exactly).
    #[serde(default)]
    pub git_dirty: bool,
    /// `rustc --version` of the first session's build.
    pub rustc: String,
    /// The first session's machine.
    pub machine: Machine,
    /// The first session's command line.
    pub command_line: Vec<String>,
    /// When the first session started, UTC, RFC 3339.
    pub started_utc: String,
    /// When the last session ended, UTC, RFC 3339 (`null` while running).
    pub finished_utc: Option<String>,
    /// The sweep's state.
    pub status: SweepStatus,
    /// Cells in the plan.
    pub planned_cells: usize,
    /// Every parameter (read back by `--resume`).
    pub params: SweepParams,
    /// How the intervals and contention flags were computed (`null` in sweeps written
    /// before they existed).
    #[serde(default)]
    pub statistics: Option<Statistics>,
    /// Every session, first to last (for a merge: every shard's, shard by shard).
    pub sessions: Vec<Session>,
    /// The plan's fingerprint ([`SweepParams::fingerprint`]), shared by every shard of one plan
    /// (absent in sweeps written before it was recorded).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub plan_fingerprint: Option<String>,
    /// For a merge of shards (`bench-sph merge`): where its cells came from.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub merge: Option<Merge>,
}

/// How a results directory was merged from shards (`meta.json`'s `merge`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Merge {
    /// The shards merged, by shard number.
    pub shards: Vec<MergedShard>,
    /// Cells of the plan that no shard had, by label (empty unless `--allow-partial`).
    pub missing_cells: Vec<String>,
    /// Cells of the plan merged without a speedup, by label: their shard's `seq` reference
    /// was left out as unusable (`--allow-partial`; absent when none).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub without_reference: Vec<String>,
    /// What the merge warned about: rows of the shards left out and why, shards whose `seq`
    /// means disagree, shards without a usable `seq`, cells missing.
    pub warnings: Vec<String>,
}

/// One shard of a merge.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MergedShard {
    /// Which shard.
    pub shard: Shard,
    /// Its results directory, as given to `bench-sph merge`.
    pub dir: String,
    /// Its state when merged.
    pub status: SweepStatus,
    /// Its cells in the merge (its `seq` cells count only where they are the merge's
    /// reference; the others are in `references.csv`).
    pub cells: usize,
}

impl Meta {
    /// The metadata of a new sweep whose first session is `session`.
    pub fn new(params: SweepParams, planned_cells: usize, session: Session) -> Meta {
        Meta {
            tool: SWEEP_TOOL.to_owned(),
            version: session.version.clone(),
            git_commit: session.git_commit.clone(),
            git_dirty: session.git_commit.ends_with("-dirty"),
            rustc: RUSTC.to_owned(),
            machine: session.machine.clone(),
            command_line: session.command_line.clone(),
            started_utc: session.started_utc.clone(),
            finished_utc: None,
            status: SweepStatus::Running,
            planned_cells,
            statistics: Some(Statistics::current(params.seed)),
            plan_fingerprint: Some(params.fingerprint()),
            params,
            sessions: vec![session],
            merge: None,
        }
    }

    /// Marks the latest session (and the sweep) ended now with `status`.
    pub fn finish(&mut self, status: SweepStatus, cells_run: usize) {
        let now = now_utc();
        if let Some(s) = self.sessions.last_mut() {
            s.finished_utc = Some(now.clone());
            s.status = status;
            s.cells_run = cells_run;
        }
        self.finished_utc = Some(now);
        self.status = status;
    }

    /// Reads `path` (a regular file of at most [`capped::META_JSON`]'s cap).
    pub fn read(path: &Path) -> anyhow::Result<Meta> {
        let bytes = capped::read(path, capped::META_JSON)?;
        serde_json::from_slice(&bytes)
            .with_context(|| format!("'{}' is not a bench-sph sweep's meta.json", path.display()))
    }

    /// Writes `path` whole (through a temporary file renamed over it, so a crash never leaves
    /// half a file).
    pub fn write(&self, path: &Path) -> anyhow::Result<()> {
        let mut text = serde_json::to_string_pretty(self)?;
        text.push('\n');
        crate::output::atomic::write(path, text.as_bytes())
    }

    /// Whether `path` is a sweep's `meta.json` (by its `tool` field): false for a missing
    /// file or another tool's JSON; an error for a file that cannot be read (not a regular
    /// file, beyond the cap).
    pub fn is_sweep_meta(path: &Path) -> anyhow::Result<bool> {
        let Some(bytes) = capped::read_if_exists(path, capped::META_JSON)? else {
            return Ok(false);
        };
        Ok(serde_json::from_slice::<serde_json::Value>(&bytes)
            .is_ok_and(|v| v["tool"] == SWEEP_TOOL))
    }
}

/// Now, UTC, RFC 3339 to the second, e.g. `2026-11-22T03:15:00Z`.
pub fn now_utc() -> String {
    chrono::Utc::now().to_rfc3339_opts(chrono::SecondsFormat::Secs, true)
}

/// Now, UTC, as a directory name, e.g. `2026-11-22T031500Z`.
pub fn timestamp_dir_name() -> String {
    chrono::Utc::now().format("%Y-%m-%dT%H%M%SZ").to_string()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_cpu_model_comes_from_model_name_or_an_arm_style_field() {
        let x86 = "processor\t: 0\nvendor_id\t: GenuineIntel\nmodel name\t: Intel(R) Xeon(R) CPU @ 2.20GHz\n";
        assert_eq!(
            cpu_model(x86).as_deref(),
            Some("Intel(R) Xeon(R) CPU @ 2.20GHz")
        );
        assert_eq!(
            cpu_model("Hardware\t: BCM2835\n").as_deref(),
            Some("BCM2835")
        );
        assert_eq!(cpu_model("processor : 0\n"), None);
    }

    #[test]
    fn the_os_name_is_pretty_name_unquoted() {
        let text = "NAME=\"Ubuntu\"\nPRETTY_NAME=\"Ubuntu 24.04.1 LTS\"\nID=ubuntu\n";
        assert_eq!(pretty_name(text).as_deref(), Some("Ubuntu 24.04.1 LTS"));
        assert_eq!(pretty_name("ID=x\n"), None);
    }

    #[test]
    fn the_build_facts_are_filled_in() {
        assert!(RUSTC.starts_with("rustc ") || RUSTC == "unknown", "{RUSTC}");
        assert!(!GIT_COMMIT.is_empty());
        let m = Machine::detect();
        assert!(m.hardware_threads >= 1);
        assert!(!m.cpu_model.is_empty() && !m.os.is_empty() && !m.kernel.is_empty());
    }

    #[test]
    fn a_meta_json_without_topology_still_loads_with_the_topology_unknown() {
        let mut meta: serde_json::Value = serde_json::from_str(include_str!(
            "../../../tests/fixtures/report-results/meta.json"
        ))
        .unwrap();
        // Whatever the fixture holds now, take the topology out as older files lack it.
        meta["machine"].as_object_mut().unwrap().remove("topology");
        for session in meta["sessions"].as_array_mut().unwrap() {
            session["machine"]
                .as_object_mut()
                .unwrap()
                .remove("topology");
        }
        let meta: Meta = serde_json::from_value(meta).unwrap();
        assert_eq!(meta.machine.topology, Topology::default());
        assert_eq!(meta.sessions[0].machine.topology, Topology::default());
        assert!(meta.machine.hardware_threads >= 1);
        // And a machine with its topology reads back the same.
        let machine = Machine::detect();
        let json = serde_json::to_string(&machine).unwrap();
        assert_eq!(serde_json::from_str::<Machine>(&json).unwrap(), machine);
    }

    #[test]
    fn timestamps_are_utc_and_directory_names_have_no_colons() {
        assert!(now_utc().ends_with('Z'));
        let dir = timestamp_dir_name();
        assert!(dir.ends_with('Z') && !dir.contains(':'), "{dir}");
        assert_eq!(dir.len(), "2026-11-22T031500Z".len());
    }
}
