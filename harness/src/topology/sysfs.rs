//! Reading a sysfs tree: parsers (text → value, pure) and the reads under a root.
//!
//! Every read answers `None` where a file is absent, unreadable or malformed: the caller
//! leaves that field unknown rather than guessing.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

/// The highest CPU number a list may name: far above the kernel's `NR_CPUS` (8192 at most
/// today), and low enough that a malformed range like `0-4000000000` is refused instead of
/// filling memory.
const MAX_CPU: usize = 1 << 16;

/// A kernel CPU list (`0-3,8-11`, `0,4`, `5`, or empty) as ascending, distinct CPU numbers;
/// `None` for anything else (a reversed range, a non-number, a CPU above [`MAX_CPU`]).
pub(super) fn parse_cpu_list(text: &str) -> Option<Vec<usize>> {
    let mut cpus = BTreeSet::new();
    for part in text.trim().split(',').filter(|p| !p.is_empty()) {
        let number = |t: &str| t.trim().parse::<usize>().ok().filter(|&c| c <= MAX_CPU);
        let (first, last) = match part.split_once('-') {
            Some((a, b)) => (number(a)?, number(b)?),
            None => (number(part)?, number(part)?),
        };
        if first > last {
            return None;
        }
        cpus.extend(first..=last);
    }
    Some(cpus.into_iter().collect())
}

/// A cache size as sysfs writes it (`48K`, `2048K`, `32M`, `1G`) in KiB; a bare number is
/// bytes, accepted only when it is whole KiB.
pub(super) fn parse_size_kib(text: &str) -> Option<u64> {
    let text = text.trim();
    let (digits, kib_per_unit) = match text.char_indices().last()? {
        (i, 'K') => (&text[..i], 1),
        (i, 'M') => (&text[..i], 1024),
        (i, 'G') => (&text[..i], 1024 * 1024),
        _ => {
            let bytes: u64 = text.parse().ok()?;
            return bytes.is_multiple_of(1024).then_some(bytes / 1024);
        }
    };
    digits.parse::<u64>().ok()?.checked_mul(kib_per_unit)
}

/// The trimmed text of `path`, or `None` if it cannot be read.
fn read_text(path: &Path) -> Option<String> {
    std::fs::read_to_string(path)
        .ok()
        .map(|t| t.trim().to_owned())
}

/// `devices/system/cpu` under `root`.
fn cpu_dir(root: &Path) -> PathBuf {
    root.join("devices/system/cpu")
}

/// The online CPUs (`devices/system/cpu/online`).
pub(super) fn online(root: &Path) -> Option<Vec<usize>> {
    parse_cpu_list(&read_text(&cpu_dir(root).join("online"))?)
}

/// Where one logical CPU sits, as its `topology/` directory says.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub(super) struct Place {
    /// `physical_package_id` (a negative id, which some platforms write for "unknown", is
    /// `None`).
    pub package: Option<usize>,
    /// `core_id` (its meaning is the platform's; unique within a package on x86).
    pub core_id: Option<usize>,
    /// `thread_siblings_list`: every hardware thread of its core, itself included.
    pub siblings: Option<Vec<usize>>,
}

/// What `cpu{cpu}/topology/` says.
pub(super) fn place(root: &Path, cpu: usize) -> Place {
    let dir = cpu_dir(root).join(format!("cpu{cpu}/topology"));
    let number = |name: &str| read_text(&dir.join(name))?.parse().ok();
    Place {
        package: number("physical_package_id"),
        core_id: number("core_id"),
        siblings: read_text(&dir.join("thread_siblings_list")).and_then(|t| parse_cpu_list(&t)),
    }
}

/// Cache sizes of one CPU, KiB.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub(super) struct Caches {
    /// Level 1, `Data`.
    pub l1d_kib: Option<u64>,
    /// Level 2, `Unified`.
    pub l2_kib: Option<u64>,
    /// Level 3, `Unified`.
    pub l3_kib: Option<u64>,
}

/// The caches in `cpu{cpu}/cache/index*/{level,type,size}` (the first index of each kind,
/// by index number).
pub(super) fn caches(root: &Path, cpu: usize) -> Caches {
    let dir = cpu_dir(root).join(format!("cpu{cpu}/cache"));
    let mut indices: Vec<(usize, PathBuf)> = std::fs::read_dir(&dir)
        .into_iter()
        .flatten()
        .flatten()
        .filter_map(|entry| {
            let name = entry.file_name();
            let k = name.to_str()?.strip_prefix("index")?.parse().ok()?;
            Some((k, entry.path()))
        })
        .collect();
    indices.sort();
    let mut caches = Caches::default();
    for (_, index) in indices {
        let (Some(level), Some(kind), Some(size)) = (
            read_text(&index.join("level")),
            read_text(&index.join("type")),
            read_text(&index.join("size")).and_then(|s| parse_size_kib(&s)),
        ) else {
            continue;
        };
        let slot = match (level.as_str(), kind.as_str()) {
            ("1", "Data") => &mut caches.l1d_kib,
            ("2", "Unified") => &mut caches.l2_kib,
            ("3", "Unified") => &mut caches.l3_kib,
            _ => continue,
        };
        slot.get_or_insert(size);
    }
    caches
}

/// The NUMA nodes (`devices/system/node/nodeN`) whose `cpulist` holds at least one of
/// `cpus`; `None` where there is no node directory (a kernel without NUMA) or no node holds
/// any of them.
pub(super) fn numa_nodes(root: &Path, cpus: &[usize]) -> Option<usize> {
    let nodes = std::fs::read_dir(root.join("devices/system/node")).ok()?;
    let count = nodes
        .flatten()
        .filter(|entry| {
            let name = entry.file_name();
            let is_node = name
                .to_str()
                .and_then(|n| n.strip_prefix("node"))
                .is_some_and(|n| n.parse::<usize>().is_ok());
            is_node
                && read_text(&entry.path().join("cpulist"))
                    .and_then(|t| parse_cpu_list(&t))
                    .is_some_and(|list| list.iter().any(|c| cpus.contains(c)))
        })
        .count();
    (count > 0).then_some(count)
}

/// The cpufreq governor of `cpus` (`cpuN/cpufreq/scaling_governor`), if every one of them
/// has one and they agree.
pub(super) fn governor(root: &Path, cpus: &[usize]) -> Option<String> {
    let mut governors = cpus.iter().map(|c| {
        read_text(&cpu_dir(root).join(format!("cpu{c}/cpufreq/scaling_governor")))
            .filter(|g| !g.is_empty())
    });
    let first = governors.next()??;
    governors
        .all(|g| g.as_deref() == Some(first.as_str()))
        .then_some(first)
}

/// Whether turbo (boost) is on: `intel_pstate/no_turbo` = 0, or where intel_pstate does not
/// run, `cpufreq/boost` = 1.
pub(super) fn turbo(root: &Path) -> Option<bool> {
    let flag = |name: &str| match read_text(&cpu_dir(root).join(name))?.as_str() {
        "0" => Some(false),
        "1" => Some(true),
        _ => None,
    };
    flag("intel_pstate/no_turbo")
        .map(|no_turbo| !no_turbo)
        .or_else(|| flag("cpufreq/boost"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cpu_lists_read_ranges_and_single_cpus_in_ascending_order() {
        assert_eq!(
            parse_cpu_list("0-3,8-11"),
            Some(vec![0, 1, 2, 3, 8, 9, 10, 11])
        );
        assert_eq!(parse_cpu_list("0,4\n"), Some(vec![0, 4]));
        assert_eq!(parse_cpu_list("4,0-1"), Some(vec![0, 1, 4]));
        assert_eq!(parse_cpu_list("7"), Some(vec![7]));
        assert_eq!(parse_cpu_list(""), Some(vec![]));
    }

    #[test]
    fn malformed_cpu_lists_are_refused() {
        for bad in ["3-1", "a", "0-", "-1", "0,,x", "0-4000000000"] {
            assert_eq!(parse_cpu_list(bad), None, "{bad}");
        }
    }

    #[test]
    fn cache_sizes_are_kib_whatever_the_unit() {
        assert_eq!(parse_size_kib("48K"), Some(48));
        assert_eq!(parse_size_kib("2048K\n"), Some(2048));
        assert_eq!(parse_size_kib("32M"), Some(32 * 1024));
        assert_eq!(parse_size_kib("1G"), Some(1024 * 1024));
        assert_eq!(parse_size_kib("65536"), Some(64));
        assert_eq!(parse_size_kib("1000"), None);
        assert_eq!(parse_size_kib("K"), None);
        assert_eq!(parse_size_kib(""), None);
        assert_eq!(parse_size_kib("12X"), None);
    }
}
