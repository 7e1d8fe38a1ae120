//! Wall-clock and process CPU time (user + system, all threads) over a region, and the
//! foreign CPU time of the rest of the machine over the same region ([`crate::contention`]).

use std::time::{Duration, Instant};

use nix::sys::resource::{UsageWho, getrusage};

use crate::contention::{CpuTicks, Foreign, foreign_between, ticks_per_second};

/// User + system CPU time consumed by this process so far, in seconds.
pub fn process_cpu_seconds() -> f64 {
    match getrusage(UsageWho::RUSAGE_SELF) {
        Ok(u) => {
            let secs = |t: nix::sys::time::TimeVal| {
                Duration::new(t.tv_sec() as u64, t.tv_usec() as u32 * 1000)
            };
            (secs(u.user_time()) + secs(u.system_time())).as_secs_f64()
        }
        // getrusage(RUSAGE_SELF) cannot fail with valid arguments; report no time rather than panic.
        Err(_) => f64::NAN,
    }
}

/// Wall and CPU seconds of a measured region.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Elapsed {
    /// Wall-clock seconds.
    pub wall_s: f64,
    /// Process CPU seconds (user + system) over the same window.
    pub cpu_s: f64,
    /// What other work used of the machine over the same window (`None` where unknown).
    pub foreign: Option<Foreign>,
}

/// Measures a region from [`Stopwatch::start`] to [`Stopwatch::stop`].
#[derive(Debug)]
pub struct Stopwatch {
    wall: Instant,
    cpu: f64,
    ticks: Option<CpuTicks>,
}

impl Stopwatch {
    /// Starts measuring now.
    pub fn start() -> Self {
        // The machine's counters are read first and last, so their window encloses ours.
        let ticks = CpuTicks::now();
        let cpu = process_cpu_seconds();
        Stopwatch {
            wall: Instant::now(),
            cpu,
            ticks,
        }
    }

    /// Wall seconds since `start`, without reading the other clocks.
    pub fn peek_wall_s(&self) -> f64 {
        self.wall.elapsed().as_secs_f64()
    }

    /// The time since `start`.
    pub fn stop(&self) -> Elapsed {
        let wall_s = self.wall.elapsed().as_secs_f64();
        let cpu_s = process_cpu_seconds() - self.cpu;
        let foreign = match (self.ticks, CpuTicks::now()) {
            (Some(a), Some(b)) => Some(foreign_between(a, b, cpu_s, ticks_per_second())),
            _ => None,
        };
        Elapsed {
            wall_s,
            cpu_s,
            foreign,
        }
    }
}

/// What other work used of the machine over a window of `window` while this process slept:
/// (foreign CPU seconds, wall seconds); `None` without `/proc/stat`. Foreign seconds per wall
/// second is how many hardware threads other work keeps busy.
pub fn sample_now(window: Duration) -> Option<(f64, f64)> {
    let watch = Stopwatch::start();
    std::thread::sleep(window);
    let elapsed = watch.stop();
    Some((elapsed.foreign?.cpu_s, elapsed.wall_s))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn on_linux_a_window_reads_the_counters_and_elsewhere_gives_nothing() {
        let busy = sample_now(Duration::from_millis(20));
        if std::path::Path::new("/proc/stat").exists() {
            let (foreign, wall) = busy.expect("Linux has /proc/stat");
            assert!(foreign >= 0.0 && foreign.is_finite() && wall >= 0.02);
        } else {
            assert!(busy.is_none());
        }
    }
}
