//! What the rest of the machine was doing while we measured: the evidence that a timing is
//! contaminated.
//!
//! On Linux, `/proc/stat` counts each CPU's time since boot (its `cpuN` lines; we sum those of
//! the CPUs in this process's affinity mask, or the machine's `cpu` line where the mask is
//! unknown), in ticks of
//! `sysconf(_SC_CLK_TCK)` (USER_HZ, 100 per second on every mainstream architecture). Over a
//! window, the machine's **busy** time is the growth of
//! `user + nice + system + irq + softirq + steal` (guest time is already inside user and nice); the **foreign** CPU time is that
//! busy time minus this process's own user + system time over the same window
//! (`getrusage`): work of other processes, of the kernel on their behalf, and of the
//! hypervisor (`steal`: time a virtual CPU was ready but the host ran something else). It is
//! clamped at zero, since the two clocks tick differently.
//!
//! The counters advance in whole ticks (10 ms), so a window's foreign time is uncertain by
//! about a tick per CPU at each end; [`Threshold`] allows for that. Elsewhere (no
//! `/proc/stat`) every reading is `None`, and the CSV columns stay empty: nothing is invented.

/// The share of the machine's capacity (hardware threads × wall seconds) that foreign work
/// may take before a trial counts as contended: 5 %.
pub const CONTENDED_SHARE: f64 = 0.05;

/// The shortest window over which a sweep judges contention, wall seconds: a tick per CPU at
/// each end of it is then at most a fifth of the [`CONTENDED_SHARE`] the threshold allows (see
/// `crate::sweep::windows`).
pub const WINDOW_S: f64 = 1.0;

/// The cumulative CPU counters of `/proc/stat`'s `cpu` line, in ticks.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CpuTicks {
    /// user + nice + system + irq + softirq + steal.
    pub busy: u64,
    /// steal alone (`None` on kernels that do not report it).
    pub steal: Option<u64>,
}

impl CpuTicks {
    /// Parses the first (`cpu `) line of `/proc/stat` text: the whole machine.
    pub fn parse(proc_stat: &str) -> Option<CpuTicks> {
        let line = proc_stat.lines().find(|l| l.starts_with("cpu "))?;
        CpuTicks::parse_line(line)
    }

    /// Sums the `cpuN` lines of `/proc/stat` text for the CPUs in `cpus` only (those this
    /// process may run on: under `taskset` or a container's cpuset, work on the others does
    /// not compete with us). `None` if any of them is missing.
    pub fn parse_cpus(proc_stat: &str, cpus: &[usize]) -> Option<CpuTicks> {
        let mut total = CpuTicks {
            busy: 0,
            steal: Some(0),
        };
        let mut found = 0;
        for line in proc_stat.lines() {
            let Some(rest) = line.strip_prefix("cpu") else {
                continue;
            };
            let Some((number, _)) = rest.split_once(' ') else {
                continue;
            };
            let Ok(cpu) = number.parse::<usize>() else {
                continue;
            };
            if !cpus.contains(&cpu) {
                continue;
            }
            let t = CpuTicks::parse_line(line)?;
            total.busy += t.busy;
            total.steal = total.steal.zip(t.steal).map(|(a, b)| a + b);
            found += 1;
        }
        (found == cpus.len()).then_some(total)
    }

    /// One `cpu…` line's counters.
    fn parse_line(line: &str) -> Option<CpuTicks> {
        let fields: Vec<u64> = line
            .split_whitespace()
            .skip(1)
            .map(|f| f.parse().ok())
            .collect::<Option<Vec<u64>>>()?;
        // user nice system idle iowait irq softirq [steal [guest [guest_nice]]]
        if fields.len() < 7 {
            return None;
        }
        let steal = fields.get(7).copied();
        let busy = fields[0] + fields[1] + fields[2] + fields[5] + fields[6] + steal.unwrap_or(0);
        Some(CpuTicks { busy, steal })
    }

    /// The counters now, of the CPUs this process may run on (the whole machine where the
    /// affinity mask cannot be read); `None` where `/proc/stat` cannot be read.
    pub fn now() -> Option<CpuTicks> {
        let text = std::fs::read_to_string("/proc/stat").ok()?;
        match allowed_cpus() {
            Some(cpus) => CpuTicks::parse_cpus(&text, cpus).or_else(|| CpuTicks::parse(&text)),
            None => CpuTicks::parse(&text),
        }
    }
}

/// The CPUs this process may run on (its affinity mask, read once: later changes, such as
/// pinning the main thread, do not show), ascending, or `None` if unknown.
pub(crate) fn allowed_cpus() -> Option<&'static [usize]> {
    static CPUS: std::sync::OnceLock<Option<Vec<usize>>> = std::sync::OnceLock::new();
    CPUS.get_or_init(|| {
        let set = nix::sched::sched_getaffinity(nix::unistd::Pid::from_raw(0)).ok()?;
        let cpus: Vec<usize> = (0..nix::sched::CpuSet::count())
            .filter(|&i| set.is_set(i).unwrap_or(false))
            .collect();
        (!cpus.is_empty()).then_some(cpus)
    })
    .as_deref()
}

/// Ticks per second of `/proc/stat` (USER_HZ).
pub fn ticks_per_second() -> f64 {
    match nix::unistd::sysconf(nix::unistd::SysconfVar::CLK_TCK) {
        Ok(Some(hz)) if hz > 0 => hz as f64,
        _ => 100.0,
    }
}

/// What other work did over a window.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Foreign {
    /// Busy CPU seconds of the machine not spent by this process (≥ 0).
    pub cpu_s: f64,
    /// Of the busy time, seconds stolen by the hypervisor (`None` when not reported).
    pub steal_s: Option<f64>,
}

/// The foreign CPU time between two readings, given this process's CPU seconds over the
/// same window.
pub fn foreign_between(start: CpuTicks, end: CpuTicks, own_cpu_s: f64, hz: f64) -> Foreign {
    let busy_s = end.busy.saturating_sub(start.busy) as f64 / hz;
    let steal_s = match (start.steal, end.steal) {
        (Some(a), Some(b)) => Some(b.saturating_sub(a) as f64 / hz),
        _ => None,
    };
    Foreign {
        cpu_s: (busy_s - own_cpu_s).max(0.0),
        steal_s,
    }
}

/// The 1-minute load average from `/proc/loadavg` text.
pub fn parse_load1(loadavg: &str) -> Option<f64> {
    loadavg
        .split_whitespace()
        .next()?
        .parse()
        .ok()
        .filter(|v: &f64| v.is_finite())
}

/// The 1-minute load average now (`None` where `/proc/loadavg` cannot be read).
pub fn load1() -> Option<f64> {
    parse_load1(&std::fs::read_to_string("/proc/loadavg").ok()?)
}

/// When foreign work makes a trial's time untrustworthy.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Threshold {
    /// The machine's hardware threads.
    pub hardware_threads: usize,
    /// Ticks per second of the counters (their resolution).
    pub hz: f64,
}

impl Threshold {
    /// The foreign CPU seconds a window of `wall_s` may contain before it counts as
    /// contended, for a cell using `cores` threads: the smaller of [`CONTENDED_SHARE`] of the
    /// machine's capacity and the hardware threads the cell leaves idle plus half a thread
    /// (so that on a large machine one busy process still counts against a cell that uses
    /// every core), plus the counters' resolution (one tick per hardware thread at each end
    /// of the window).
    pub fn allowed_s(&self, wall_s: f64, cores: usize) -> f64 {
        let threads = self.hardware_threads as f64;
        let share = CONTENDED_SHARE * threads;
        let idle = self.hardware_threads.saturating_sub(cores) as f64 + 0.5;
        share.min(idle) * wall_s + 2.0 * threads / self.hz
    }

    /// Whether `foreign_cpu_s` over `wall_s` is too much for a cell of `cores` threads.
    pub fn exceeded(&self, foreign_cpu_s: f64, wall_s: f64, cores: usize) -> bool {
        foreign_cpu_s > self.allowed_s(wall_s, cores)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const STAT_A: &str = "cpu  100300 0 8268 260661 640 0 81 237 0 0\ncpu0 1 2 3 4 5 6 7 8 0 0\n";
    const STAT_B: &str = "cpu  100500 10 8278 260861 640 0 81 257 0 0\ncpu0 1 2 3 4 5 6 7 8 0 0\n";

    #[test]
    fn busy_ticks_sum_user_nice_system_irq_softirq_and_steal() {
        let a = CpuTicks::parse(STAT_A).unwrap();
        assert_eq!(a.busy, 100300 + 8268 + 81 + 237);
        assert_eq!(a.steal, Some(237));
        // An old kernel without steal.
        let old = CpuTicks::parse("cpu  10 1 2 300 4 5 6\n").unwrap();
        assert_eq!((old.busy, old.steal), (24, None));
        assert_eq!(CpuTicks::parse("cpu0 1 2 3\n"), None);
        // Only the CPUs we may run on: cpu1 is busy with someone else's work.
        let stat = "cpu  30 0 0 0 0 0 0 0\ncpu0 10 0 0 0 0 0 0 0\ncpu1 20 0 0 0 0 0 0 0\n";
        assert_eq!(CpuTicks::parse_cpus(stat, &[0]).unwrap().busy, 10);
        assert_eq!(CpuTicks::parse_cpus(stat, &[0, 1]).unwrap().busy, 30);
        assert_eq!(CpuTicks::parse_cpus(stat, &[2]), None);
        assert_eq!(CpuTicks::parse("cpu  1 2 x 4 5 6 7\n"), None);
    }

    #[test]
    fn foreign_time_is_the_machines_busy_time_less_our_own() {
        let (a, b) = (
            CpuTicks::parse(STAT_A).unwrap(),
            CpuTicks::parse(STAT_B).unwrap(),
        );
        // busy grew by 200 + 10 + 10 + 20 = 240 ticks = 2.4 s; we used 1.5 s.
        let f = foreign_between(a, b, 1.5, 100.0);
        assert!((f.cpu_s - 0.9).abs() < 1e-12, "{f:?}");
        assert_eq!(f.steal_s, Some(0.2));
        // Our own time measured a hair above the ticks: clamped at zero, not negative.
        assert_eq!(foreign_between(a, b, 2.5, 100.0).cpu_s, 0.0);
    }

    #[test]
    fn the_load_average_is_the_first_field() {
        assert_eq!(parse_load1("0.31 0.91 0.72 1/84 6978\n"), Some(0.31));
        assert_eq!(parse_load1(""), None);
        assert_eq!(parse_load1("nan 1 1"), None);
    }

    #[test]
    fn the_threshold_is_five_percent_of_capacity_plus_the_tick_resolution() {
        let t = Threshold {
            hardware_threads: 2,
            hz: 100.0,
        };
        // 5 % of 2 threads × 1 s = 0.1 s, plus 2 ticks × 2 threads = 0.04 s.
        assert!((t.allowed_s(1.0, 2) - 0.14).abs() < 1e-12);
        assert!(!t.exceeded(0.14, 1.0, 2));
        assert!(t.exceeded(0.15, 1.0, 2));
        // One core of two kept busy by another process is far beyond it.
        assert!(t.exceeded(1.0, 1.0, 2));
        // On 64 threads, one busy thread (10 s of foreign CPU over 10 s) is 1.6 % of the
        // machine, but a cell using all 64 has no idle thread to absorb it; a 1-core cell has
        // 63.
        let big = Threshold {
            hardware_threads: 64,
            hz: 100.0,
        };
        assert!(big.exceeded(10.0, 10.0, 64));
        assert!(!big.exceeded(10.0, 10.0, 1));
    }
}
