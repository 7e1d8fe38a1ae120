//! Wall-clock and process CPU time (user + system, all threads) over a region.

use std::time::{Duration, Instant};

use nix::sys::resource::{UsageWho, getrusage};

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
}

/// Measures a region from [`Stopwatch::start`] to [`Stopwatch::stop`].
#[derive(Debug)]
pub struct Stopwatch {
    wall: Instant,
    cpu: f64,
}

impl Stopwatch {
    /// Starts measuring now.
    pub fn start() -> Self {
        let cpu = process_cpu_seconds();
        Stopwatch {
            wall: Instant::now(),
            cpu,
        }
    }

    /// The time since `start`.
    pub fn stop(&self) -> Elapsed {
        let wall_s = self.wall.elapsed().as_secs_f64();
        Elapsed {
            wall_s,
            cpu_s: process_cpu_seconds() - self.cpu,
        }
    }
}
