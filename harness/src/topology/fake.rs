//! Fake sysfs trees for the tests: the machines of the topology tests, built once here.

use std::path::Path;

use tempfile::TempDir;

/// A sysfs tree in a temporary directory (removed when dropped).
pub(crate) struct FakeSys {
    dir: TempDir,
}

impl FakeSys {
    /// An empty tree.
    pub(crate) fn new() -> FakeSys {
        FakeSys {
            dir: tempfile::tempdir().unwrap(),
        }
    }

    /// The tree's root (what `/sys` is to the real one).
    pub(crate) fn root(&self) -> &Path {
        self.dir.path()
    }

    /// Writes `text` at `path` (relative to the root), creating its directories.
    pub(crate) fn file(&self, path: &str, text: &str) -> &FakeSys {
        let path = self.root().join(path);
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(path, format!("{text}\n")).unwrap();
        self
    }

    /// Logical CPU `cpu` on core `core_id` of `package`, whose core's threads are `siblings`
    /// (a kernel CPU list), with a 48K L1d (and a 32K L1i), 2048K L2 and 32M L3 and the
    /// `performance` governor.
    pub(crate) fn cpu(
        &self,
        cpu: usize,
        package: usize,
        core_id: usize,
        siblings: &str,
    ) -> &FakeSys {
        let dir = format!("devices/system/cpu/cpu{cpu}");
        self.file(
            &format!("{dir}/topology/physical_package_id"),
            &package.to_string(),
        )
        .file(&format!("{dir}/topology/core_id"), &core_id.to_string())
        .file(&format!("{dir}/topology/thread_siblings_list"), siblings)
        .file(&format!("{dir}/cpufreq/scaling_governor"), "performance");
        for (index, level, kind, size) in [
            (0, 1, "Data", "48K"),
            (1, 1, "Instruction", "32K"),
            (2, 2, "Unified", "2048K"),
            (3, 3, "Unified", "32M"),
        ] {
            let index = format!("{dir}/cache/index{index}");
            self.file(&format!("{index}/level"), &level.to_string())
                .file(&format!("{index}/type"), kind)
                .file(&format!("{index}/size"), size);
        }
        self
    }
}

/// One package of 4 cores × 2 threads, one NUMA node, turbo on (intel_pstate): cpuN and
/// cpuN+4 are the two threads of core N, as Intel machines number them.
pub(crate) fn smt_4x2() -> FakeSys {
    let sys = FakeSys::new();
    sys.file("devices/system/cpu/online", "0-7")
        .file("devices/system/cpu/intel_pstate/no_turbo", "0")
        .file("devices/system/node/node0/cpulist", "0-7");
    for core in 0..4 {
        let siblings = format!("{core},{}", core + 4);
        sys.cpu(core, 0, core, &siblings)
            .cpu(core + 4, 0, core, &siblings);
    }
    sys
}

/// Two packages × 2 cores × 1 thread, one NUMA node per package, boost off (acpi-cpufreq):
/// even CPUs on package 0, odd ones on package 1, and each package numbers its cores 0 and 1
/// (so only the pair (package, core id) names a core).
pub(crate) fn two_sockets() -> FakeSys {
    let sys = FakeSys::new();
    sys.file("devices/system/cpu/online", "0-3")
        .file("devices/system/cpu/cpufreq/boost", "0")
        .file("devices/system/node/node0/cpulist", "0,2")
        .file("devices/system/node/node1/cpulist", "1,3");
    for cpu in 0..4 {
        sys.cpu(cpu, cpu % 2, cpu / 2, &cpu.to_string());
    }
    sys
}
