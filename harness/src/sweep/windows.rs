//! Contention judged over windows long enough for the machine's counters.
//!
//! `/proc/stat` counts CPU time in ticks of 10 ms per CPU, so the foreign CPU time of one
//! short run is unknowable: a 5 ms run beside a busy loop reads 0 or 1 tick, and the
//! allowance for the counters' resolution ([`Threshold::allowed_s`]) swallows it. So runs are
//! judged together: a **window** opens before a run and closes after the first run that
//! brings it to at least [`WINDOW_S`] of wall time (or at the end of a phase, or before the
//! sweep waits for a quiet machine). Its foreign CPU time — the machine's busy time, steal
//! included, less this process's own — over its wall time is how many hardware threads other
//! work kept busy, and every run in it is judged by that share against its own cell's
//! threshold. A window shorter than [`WINDOW_S`] at the end of a phase is judged together
//! with the window before it (their counters are contiguous), so the last runs of a phase are
//! not judged on a few ticks.
//!
//! With `--fake-contention` (tests) a run's foreign time is its fake share of the machine
//! over its (fake) wall time, and a window sums them.

use crate::clock::Stopwatch;
use crate::contention::Threshold;

pub use crate::contention::WINDOW_S;

/// The verdict on one run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Verdict {
    /// Hardware threads' worth of CPU other work used over the run's window.
    pub foreign_threads: Option<f64>,
    /// Whether that is too much for the run's cell.
    pub contended: Option<bool>,
}

/// What a closed window measured: foreign CPU seconds over wall seconds.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Reading {
    foreign_s: f64,
    wall_s: f64,
}

/// Windows over a sequence of runs, each run named by a key `K`.
#[derive(Debug)]
pub struct Windows<K> {
    threshold: Threshold,
    fake: bool,
    watch: Option<Stopwatch>,
    /// Fake foreign and wall seconds summed over the open window's runs.
    fake_sum: Reading,
    /// The open window's runs: key and cores.
    runs: Vec<(K, usize)>,
    /// The last window closed, for a short window at the end of a phase.
    previous: Option<Reading>,
}

impl<K> Windows<K> {
    /// Windows judged by `threshold`, on the machine's counters or (`fake`) on the runs' fake
    /// shares.
    pub fn new(threshold: Threshold, fake: bool) -> Self {
        Windows {
            threshold,
            fake,
            watch: None,
            fake_sum: Reading {
                foreign_s: 0.0,
                wall_s: 0.0,
            },
            runs: Vec::new(),
            previous: None,
        }
    }

    /// Call before each run: opens a window when none is open.
    pub fn before_run(&mut self) {
        if self.runs.is_empty() && self.watch.is_none() && !self.fake {
            self.watch = Some(Stopwatch::start());
        }
    }

    /// Call after each run with its key, its cell's cores, and (with fake contention) its fake
    /// foreign and wall seconds. Returns the verdicts of the window's runs when this run closed
    /// it, in run order.
    pub fn after_run(
        &mut self,
        key: K,
        cores: usize,
        fake: Option<(f64, f64)>,
    ) -> Vec<(K, Verdict)> {
        self.runs.push((key, cores));
        if let Some((foreign_s, wall_s)) = fake {
            self.fake_sum.foreign_s += foreign_s;
            self.fake_sum.wall_s += wall_s;
        }
        let wall_s = match (&self.watch, self.fake) {
            (_, true) => self.fake_sum.wall_s,
            (Some(w), false) => w.peek_wall_s(),
            (None, false) => 0.0,
        };
        if wall_s >= WINDOW_S {
            self.close_window(false)
        } else {
            Vec::new()
        }
    }

    /// Closes the open window (the end of a phase, or a pause): its runs' verdicts, a short
    /// window judged together with the one before it.
    pub fn close(&mut self) -> Vec<(K, Verdict)> {
        let out = self.close_window(true);
        // What follows a pause is not contiguous with what came before.
        self.previous = None;
        out
    }

    fn close_window(&mut self, at_end: bool) -> Vec<(K, Verdict)> {
        let reading = if self.fake {
            Some(std::mem::replace(
                &mut self.fake_sum,
                Reading {
                    foreign_s: 0.0,
                    wall_s: 0.0,
                },
            ))
        } else {
            self.watch.take().and_then(|w| {
                let e = w.stop();
                Some(Reading {
                    foreign_s: e.foreign?.cpu_s,
                    wall_s: e.wall_s,
                })
            })
        };
        let runs = std::mem::take(&mut self.runs);
        if runs.is_empty() {
            return Vec::new();
        }
        let judged = match (reading, self.previous) {
            (Some(r), Some(p)) if at_end && r.wall_s < WINDOW_S => Some(Reading {
                foreign_s: r.foreign_s + p.foreign_s,
                wall_s: r.wall_s + p.wall_s,
            }),
            (r, _) => r,
        };
        self.previous = reading;
        runs.into_iter()
            .map(|(key, cores)| {
                let verdict = match judged {
                    Some(r) if r.wall_s > 0.0 => Verdict {
                        foreign_threads: Some(r.foreign_s / r.wall_s),
                        contended: Some(self.threshold.exceeded(r.foreign_s, r.wall_s, cores)),
                    },
                    _ => Verdict {
                        foreign_threads: None,
                        contended: None,
                    },
                };
                (key, verdict)
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn two_threads() -> Threshold {
        Threshold {
            hardware_threads: 2,
            hz: 100.0,
        }
    }

    /// Fake runs of `wall` seconds beside `busy` of the machine's two threads.
    fn run_all(walls: &[f64], busy: f64) -> Vec<(usize, Verdict)> {
        let mut w = Windows::new(two_threads(), true);
        let mut out = Vec::new();
        for (i, &wall) in walls.iter().enumerate() {
            w.before_run();
            out.extend(w.after_run(i, 2, Some((busy * 2.0 * wall, wall))));
        }
        out.extend(w.close());
        out
    }

    #[test]
    fn short_runs_beside_a_busy_loop_are_each_flagged() {
        // 400 runs of 5 ms beside one busy thread of two: every run flagged, in run order.
        let verdicts = run_all(&[0.005; 400], 0.5);
        assert_eq!(verdicts.len(), 400);
        assert!(verdicts.iter().enumerate().all(|(i, (k, _))| *k == i));
        assert!(verdicts.iter().all(|(_, v)| v.contended == Some(true)));
        assert!((verdicts[0].1.foreign_threads.unwrap() - 1.0).abs() < 1e-9);
        // One such run alone is lost in the counters' resolution.
        assert_eq!(run_all(&[0.005], 0.5)[0].1.contended, Some(false));
    }

    #[test]
    fn a_quiet_machine_flags_nothing() {
        let verdicts = run_all(&[0.005; 400], 0.01);
        assert!(verdicts.iter().all(|(_, v)| v.contended == Some(false)));
    }

    #[test]
    fn windows_close_at_a_second_and_a_short_last_one_is_judged_with_the_one_before() {
        let mut w = Windows::new(two_threads(), true);
        // 0.6 s quiet, 0.6 s quiet (closes at 1.2 s), then a 0.01 s run beside a busy thread.
        w.before_run();
        assert!(w.after_run(0, 2, Some((0.0, 0.6))).is_empty());
        w.before_run();
        let first = w.after_run(1, 2, Some((0.0, 0.6)));
        assert_eq!(first.len(), 2);
        assert!(first.iter().all(|(_, v)| v.contended == Some(false)));
        w.before_run();
        assert!(w.after_run(2, 2, Some((0.02, 0.01))).is_empty());
        let last = w.close();
        // 0.02 s of foreign time over 1.21 s: quiet, where on its own the run would read
        // both threads busy (and still pass, inside the tick allowance).
        assert_eq!(last.len(), 1);
        assert!((last[0].1.foreign_threads.unwrap() - 0.02 / 1.21).abs() < 1e-12);
        assert_eq!(last[0].1.contended, Some(false));
    }

    #[test]
    fn each_run_is_judged_against_its_own_cores() {
        // 16 threads, one busy: a 16-core cell has no idle thread to absorb it, a 1-core
        // cell has 15.
        let t = Threshold {
            hardware_threads: 16,
            hz: 100.0,
        };
        let mut w = Windows::new(t, true);
        w.before_run();
        w.after_run("wide", 16, Some((0.5, 0.5)));
        w.before_run();
        let v = w.after_run("narrow", 1, Some((0.5, 0.5)));
        assert_eq!(v[0].1.contended, Some(true));
        assert_eq!(v[1].1.contended, Some(false));
    }

    #[test]
    fn real_windows_read_the_counters_where_there_are_some() {
        let mut w = Windows::new(two_threads(), false);
        w.before_run();
        std::thread::sleep(std::time::Duration::from_millis(5));
        assert!(w.after_run((), 1, None).is_empty());
        let v = w.close();
        assert_eq!(v.len(), 1);
        let known = std::path::Path::new("/proc/stat").exists();
        assert_eq!(v[0].1.foreign_threads.is_some(), known);
    }
}
