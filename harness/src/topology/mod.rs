//! The machine's topology as far as this process can use it: which logical CPUs it may run
//! on, how they group into physical cores (SMT siblings), sockets and NUMA nodes, the cache
//! sizes, and the frequency policy; and, from that, the orders worker threads would be pinned
//! in ([`Pin`]) and how many threads share a core ([`SmtSplit`]).
//!
//! Everything is read from sysfs (`/sys/devices/system/{cpu,node}`), restricted to the CPUs of
//! the process's affinity mask (under `taskset` or a container's cpuset, the other CPUs are
//! not ours). It is metadata: nothing here fails or panics, and whatever cannot be read stays
//! unknown (`None`, or an empty list) rather than guessed. Without sysfs only
//! [`Topology::logical_cpus`] (and [`Topology::cpus`] where the mask is known) is filled in.
//!
//! [`Topology::logical_cpus`] counts the affinity mask; `hardware_threads` in `meta.json`
//! ([`crate::results::meta::Machine`]) is `available_parallelism`, which also honours a
//! cgroup CPU quota, so the two can differ inside a container.

#[cfg(test)]
pub(crate) mod fake;
mod order;
mod sysfs;

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

use serde::{Deserialize, Serialize};

pub use order::{Pin, SmtSplit, UnknownPin};

/// The machine's topology, restricted to the logical CPUs this process may run on.
///
/// [`Default`] is a topology nothing was read of (`logical_cpus` 0): what a `meta.json`
/// written before topology was recorded holds.
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(default)]
pub struct Topology {
    /// Logical CPUs (hardware threads) the process may run on: its affinity mask, or where
    /// that is unknown the online CPUs, or failing both `available_parallelism`. At least 1,
    /// except in [`Topology::default`].
    pub logical_cpus: usize,
    /// Those CPUs' numbers, ascending (empty where neither the mask nor sysfs is readable).
    pub cpus: Vec<usize>,
    /// Physical cores holding at least one of those CPUs.
    pub physical_cores: Option<usize>,
    /// Hardware threads of one core that the process may use, the most over its cores. Cores
    /// can differ (a hybrid CPU's performance cores have 2 threads, its efficiency cores 1;
    /// an affinity mask may leave out some siblings): this is the largest, so `physical_cores
    /// × threads_per_core` may exceed `logical_cpus`; [`Topology::siblings`] has each core's.
    pub threads_per_core: Option<usize>,
    /// Sockets (physical packages) holding at least one of those CPUs.
    pub sockets: Option<usize>,
    /// NUMA nodes holding at least one of those CPUs (`None` on a kernel without NUMA).
    pub numa_nodes: Option<usize>,
    /// One list per physical core of its logical CPUs that the process may use, ascending; a
    /// core with one usable thread has a one-CPU list, so together they hold every CPU of
    /// [`Topology::cpus`]. Cores are in placement order: by package, then core id (then
    /// lowest CPU). Empty where unknown.
    pub siblings: Vec<Vec<usize>>,
    /// Level 1 data cache of the first usable CPU, KiB (hybrid CPUs' cores differ).
    pub l1d_kib: Option<u64>,
    /// Level 2 (unified) cache of the first usable CPU, KiB: one instance, which sysfs's
    /// `shared_cpu_list` says which CPUs share.
    pub l2_kib: Option<u64>,
    /// Level 3 (unified) cache of the first usable CPU, KiB: one instance, usually shared by
    /// a whole package (or a chiplet).
    pub l3_kib: Option<u64>,
    /// The cpufreq governor of the usable CPUs (e.g. `performance`, `powersave`, `schedutil`),
    /// `None` where there is no cpufreq (most virtual machines) or the CPUs' governors differ.
    pub governor: Option<String>,
    /// Whether turbo (boost) frequencies are enabled: `intel_pstate/no_turbo` = 0, or where
    /// intel_pstate does not run, `cpufreq/boost` = 1.
    pub turbo: Option<bool>,
}

impl Topology {
    /// This machine's topology: `/sys`, restricted to the process's affinity mask.
    pub fn detect() -> Topology {
        let allowed = crate::contention::allowed_cpus().unwrap_or(&[]);
        Topology::read(Path::new("/sys"), allowed)
    }

    /// The topology under the sysfs tree at `root` (`/sys` normally), restricted to the
    /// logical CPUs in `allowed` (the affinity mask; empty when unknown, and then the online
    /// CPUs are used). The mask only ever holds online CPUs, the kernel sees to that, so
    /// `online` is read only when the mask is unknown.
    pub fn read(root: &Path, allowed: &[usize]) -> Topology {
        let cpus: Vec<usize> = if allowed.is_empty() {
            sysfs::online(root).unwrap_or_default()
        } else {
            let set: BTreeSet<usize> = allowed.iter().copied().collect();
            set.into_iter().collect()
        };
        let Some(&first) = cpus.first() else {
            return Topology {
                logical_cpus: std::thread::available_parallelism().map_or(1, |n| n.get()),
                ..Topology::default()
            };
        };
        let places: Vec<sysfs::Place> = cpus.iter().map(|&c| sysfs::place(root, c)).collect();
        let siblings = cores(&cpus, &places).unwrap_or_default();
        let sockets = places
            .iter()
            .map(|p| p.package)
            .collect::<Option<BTreeSet<usize>>>()
            .map(|packages| packages.len());
        let caches = sysfs::caches(root, first);
        Topology {
            logical_cpus: cpus.len(),
            physical_cores: (!siblings.is_empty()).then_some(siblings.len()),
            threads_per_core: siblings.iter().map(Vec::len).max(),
            sockets,
            numa_nodes: sysfs::numa_nodes(root, &cpus),
            siblings,
            l1d_kib: caches.l1d_kib,
            l2_kib: caches.l2_kib,
            l3_kib: caches.l3_kib,
            governor: sysfs::governor(root, &cpus),
            turbo: sysfs::turbo(root),
            cpus,
        }
    }
}

/// The physical cores of `cpus` (ascending, `places[i]` is `cpus[i]`'s) as lists of their
/// CPUs, in placement order; `None` unless every CPU has a sibling list and the lists agree.
///
/// A core is a distinct `thread_siblings_list`, the kernel's own grouping: it is the same as
/// a distinct (package, core id) on x86, and stays right where a platform repeats core ids
/// (per die, say). The lists agree when each names its own CPU and every usable CPU it names
/// has the same list.
fn cores(cpus: &[usize], places: &[sysfs::Place]) -> Option<Vec<Vec<usize>>> {
    let mut by_list: BTreeMap<&[usize], Vec<usize>> = BTreeMap::new();
    for (&cpu, place) in cpus.iter().zip(places) {
        let list = place.siblings.as_deref().filter(|l| l.contains(&cpu))?;
        // `cpus` is ascending, so each core's CPUs are too.
        by_list.entry(list).or_default().push(cpu);
    }
    let mut cores = Vec::with_capacity(by_list.len());
    for (list, members) in by_list {
        let usable: Vec<usize> = list
            .iter()
            .copied()
            .filter(|c| cpus.binary_search(c).is_ok())
            .collect();
        if usable != members {
            return None;
        }
        let place = &places[cpus.binary_search(&members[0]).ok()?];
        cores.push(((place.package, place.core_id, members[0]), members));
    }
    cores.sort();
    Some(cores.into_iter().map(|(_, members)| members).collect())
}

#[cfg(test)]
mod tests {
    use super::fake::{FakeSys, smt_4x2, two_sockets};
    use super::*;

    #[test]
    fn a_four_core_two_thread_machine_has_four_cores_of_two_siblings() {
        let sys = smt_4x2();
        let t = Topology::read(sys.root(), &[0, 1, 2, 3, 4, 5, 6, 7]);
        assert_eq!(
            t,
            Topology {
                logical_cpus: 8,
                cpus: vec![0, 1, 2, 3, 4, 5, 6, 7],
                physical_cores: Some(4),
                threads_per_core: Some(2),
                sockets: Some(1),
                numa_nodes: Some(1),
                siblings: vec![vec![0, 4], vec![1, 5], vec![2, 6], vec![3, 7]],
                l1d_kib: Some(48),
                l2_kib: Some(2048),
                l3_kib: Some(32 * 1024),
                governor: Some("performance".to_owned()),
                turbo: Some(true),
            }
        );
    }

    #[test]
    fn a_two_socket_machine_orders_its_cores_by_package_then_core_id() {
        let sys = two_sockets();
        let t = Topology::read(sys.root(), &[0, 1, 2, 3]);
        assert_eq!(t.logical_cpus, 4);
        assert_eq!(t.physical_cores, Some(4));
        assert_eq!(t.threads_per_core, Some(1));
        assert_eq!(t.sockets, Some(2));
        assert_eq!(t.numa_nodes, Some(2));
        assert_eq!(t.siblings, vec![vec![0], vec![2], vec![1], vec![3]]);
        assert_eq!(t.turbo, Some(false));
    }

    #[test]
    fn only_the_cpus_of_the_affinity_mask_count() {
        let sys = smt_4x2();
        // Both threads of core 0, one of core 1.
        let t = Topology::read(sys.root(), &[4, 1, 0]);
        assert_eq!(t.logical_cpus, 3);
        assert_eq!(t.cpus, vec![0, 1, 4]);
        assert_eq!(t.physical_cores, Some(2));
        assert_eq!(t.threads_per_core, Some(2));
        assert_eq!(t.siblings, vec![vec![0, 4], vec![1]]);
        // One thread of every core: no SMT left to the process.
        let t = Topology::read(sys.root(), &[0, 1, 2, 3]);
        assert_eq!((t.physical_cores, t.threads_per_core), (Some(4), Some(1)));
        // Package 1 only: one socket and one node.
        let sys = two_sockets();
        let t = Topology::read(sys.root(), &[1, 3]);
        assert_eq!((t.sockets, t.numa_nodes), (Some(1), Some(1)));
        assert_eq!(t.siblings, vec![vec![1], vec![3]]);
    }

    #[test]
    fn an_unknown_mask_means_the_online_cpus() {
        let sys = two_sockets();
        let t = Topology::read(sys.root(), &[]);
        assert_eq!(t.cpus, vec![0, 1, 2, 3]);
        assert_eq!(t.physical_cores, Some(4));
    }

    #[test]
    fn an_absent_tree_leaves_everything_but_the_cpus_unknown() {
        let sys = FakeSys::new();
        let absent = sys.root().join("no-such-sys");
        let t = Topology::read(&absent, &[0, 1, 2]);
        assert_eq!(
            t,
            Topology {
                logical_cpus: 3,
                cpus: vec![0, 1, 2],
                ..Topology::default()
            }
        );
        // Neither mask nor tree: only the count, from available_parallelism.
        let t = Topology::read(&absent, &[]);
        assert!(t.logical_cpus >= 1);
        assert_eq!(
            t,
            Topology {
                logical_cpus: t.logical_cpus,
                ..Topology::default()
            }
        );
    }

    #[test]
    fn sibling_lists_that_disagree_leave_the_cores_unknown_but_not_the_rest() {
        let sys = smt_4x2();
        // cpu4 no longer names cpu0 as its sibling, though cpu0 names cpu4.
        sys.file("devices/system/cpu/cpu4/topology/thread_siblings_list", "4");
        let t = Topology::read(sys.root(), &[0, 4]);
        assert_eq!(t.siblings, Vec::<Vec<usize>>::new());
        assert_eq!((t.physical_cores, t.threads_per_core), (None, None));
        assert_eq!((t.sockets, t.l1d_kib), (Some(1), Some(48)));
        // A list that leaves out its own CPU, or garbage, is no better.
        sys.file("devices/system/cpu/cpu4/topology/thread_siblings_list", "0");
        assert_eq!(Topology::read(sys.root(), &[0, 4]).physical_cores, None);
        sys.file("devices/system/cpu/cpu4/topology/thread_siblings_list", "x");
        assert_eq!(Topology::read(sys.root(), &[0, 4]).physical_cores, None);
    }

    #[test]
    fn governors_that_differ_and_a_negative_package_are_unknown() {
        let sys = two_sockets();
        sys.file(
            "devices/system/cpu/cpu3/cpufreq/scaling_governor",
            "powersave",
        );
        assert_eq!(
            Topology::read(sys.root(), &[0, 1, 2]).governor.as_deref(),
            Some("performance")
        );
        assert_eq!(Topology::read(sys.root(), &[0, 1, 2, 3]).governor, None);
        sys.file("devices/system/cpu/cpu3/topology/physical_package_id", "-1");
        assert_eq!(Topology::read(sys.root(), &[0, 1, 2, 3]).sockets, None);
    }

    #[test]
    fn this_machine_reads_as_a_consistent_topology() {
        let t = Topology::detect();
        println!("{}", serde_json::to_string_pretty(&t).unwrap());
        assert!(t.logical_cpus >= 1);
        if !t.cpus.is_empty() {
            assert_eq!(t.cpus.len(), t.logical_cpus);
        }
        if let Some(cores) = t.physical_cores {
            let threads = t.threads_per_core.unwrap();
            assert!(cores <= t.logical_cpus && cores * threads >= t.logical_cpus);
            let mut all: Vec<usize> = t.siblings.concat();
            all.sort();
            assert_eq!(all, t.cpus);
        }
    }

    #[test]
    fn a_topology_survives_json_and_missing_fields_read_as_unknown() {
        let t = Topology::read(smt_4x2().root(), &[0, 4]);
        let json = serde_json::to_string(&t).unwrap();
        assert_eq!(serde_json::from_str::<Topology>(&json).unwrap(), t);
        let partial: Topology = serde_json::from_str(r#"{"logical_cpus": 2}"#).unwrap();
        assert_eq!(
            partial,
            Topology {
                logical_cpus: 2,
                ..Topology::default()
            }
        );
    }
}
