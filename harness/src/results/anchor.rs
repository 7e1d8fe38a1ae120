//! The OpenMP anchor of a sweep (`sweep --anchor PATH`): the plain C++ loop's OpenMP build
//! (`benches/plain-loop/mueller.cpp`, each pass `omp parallel for schedule(static)`) run at
//! each of the sweep's core counts on the same machine in the same sweep, so that the report
//! can set the strategies' speedups beside a team of OpenMP threads'. Its runs are
//! [`ANCHOR_FILE`](super::ANCHOR_FILE)'s rows; [`speedups`] reads them as the report does.

use serde::{Deserialize, Serialize};

use super::intervals::{Ratio, ratio};

/// `anchor.csv`'s header.
pub const ANCHOR_COLUMNS: [&str; 9] = [
    "n",
    "steps",
    "seed",
    "threads",
    "round",
    "position",
    "wall_s",
    "checksum",
    "oversubscribed",
];

/// One run of the anchor.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AnchorRun {
    /// Particles (the group's N; the `seed` preset, all-pairs).
    pub n: usize,
    /// Steps.
    pub steps: usize,
    /// Seed of the initial jitter.
    pub seed: u64,
    /// `OMP_NUM_THREADS`.
    pub threads: usize,
    /// The round, from 1: in each round every thread count runs once, in a shuffled order.
    pub round: usize,
    /// The run's place in its round, from 1.
    pub position: usize,
    /// The loop's own time of its steps (without starting the process), seconds.
    pub wall_s: f64,
    /// The loop's checksum of its final state: bench-sph's `seq` checksum when it computed the
    /// same state.
    pub checksum: String,
    /// More threads than the machine's hardware threads.
    pub oversubscribed: bool,
}

impl AnchorRun {
    /// What makes the run impossible, if anything: no particles, steps or threads, no round,
    /// or a time that is not finite and positive.
    pub fn problem(&self) -> Option<String> {
        if self.n == 0 || self.steps == 0 || self.threads == 0 || self.round == 0 {
            return Some("n, steps, threads and round must each be at least 1".into());
        }
        if !(self.wall_s.is_finite() && self.wall_s > 0.0) {
            return Some(format!("time {} s", self.wall_s));
        }
        None
    }
}

/// The anchor's speedup at one thread count in one group.
#[derive(Debug, Clone, PartialEq)]
pub struct AnchorSpeedup {
    /// `OMP_NUM_THREADS`.
    pub threads: usize,
    /// The typical ratio of the round's 1-thread time to its `threads`-thread time (geometric
    /// mean over the rounds, with its interval), as a paired speedup.
    pub speedup: Ratio,
}

/// The anchor's speedups in the group of N = `n`, `steps` steps: at each thread count above
/// 1, the rounds' ratios of the 1-thread run to that run. Rounds without a 1-thread run (or
/// with an unusable time) are left out; a thread count with no round left has no speedup.
pub fn speedups(runs: &[AnchorRun], n: usize, steps: usize) -> Vec<AnchorSpeedup> {
    let runs: Vec<&AnchorRun> = runs
        .iter()
        .filter(|r| r.n == n && r.steps == steps)
        .collect();
    let mut threads: Vec<usize> = runs.iter().map(|r| r.threads).filter(|&t| t > 1).collect();
    threads.sort_unstable();
    threads.dedup();
    let one = |round: usize| {
        runs.iter()
            .find(|r| r.threads == 1 && r.round == round)
            .map(|r| r.wall_s)
    };
    threads
        .into_iter()
        .filter_map(|t| {
            let ratios: Vec<f64> = runs
                .iter()
                .filter(|r| r.threads == t)
                .filter_map(|r| Some(one(r.round)? / r.wall_s))
                .filter(|x| x.is_finite() && *x > 0.0)
                .collect();
            Some(AnchorSpeedup {
                threads: t,
                speedup: ratio(&ratios)?,
            })
        })
        .collect()
}

/// Whether every run of the group of N = `n`, `steps` steps ended in `checksum` (the group's
/// `seq` state), so that the anchor computed the same thing as the strategies.
pub fn same_state(runs: &[AnchorRun], n: usize, steps: usize, checksum: &str) -> bool {
    runs.iter()
        .filter(|r| r.n == n && r.steps == steps)
        .all(|r| r.checksum == checksum)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(threads: usize, round: usize, wall_s: f64) -> AnchorRun {
        AnchorRun {
            n: 100,
            steps: 10,
            seed: 1,
            threads,
            round,
            position: 1,
            wall_s,
            checksum: "ab".into(),
            oversubscribed: false,
        }
    }

    #[test]
    fn a_speedup_pairs_each_round_with_its_own_one_thread_run() {
        // Round 2 is twice as slow throughout: paired, the speedup is still exactly 2.
        let runs = [
            run(1, 1, 1.0),
            run(2, 1, 0.5),
            run(1, 2, 2.0),
            run(2, 2, 1.0),
            run(1, 3, 1.0),
            run(2, 3, 0.5),
            run(4, 3, 0.4),
        ];
        let s = speedups(&runs, 100, 10);
        assert_eq!(s.len(), 2);
        assert_eq!(s[0].threads, 2);
        assert!((s[0].speedup.value - 2.0).abs() < 1e-12);
        let i = s[0].speedup.interval.unwrap();
        assert!((i.low - 2.0).abs() < 1e-9 && (i.high - 2.0).abs() < 1e-9);
        // One round of 4 threads: its value, and no interval from one round.
        assert_eq!(s[1].threads, 4);
        assert!((s[1].speedup.value - 2.5).abs() < 1e-12);
        assert!(s[1].speedup.interval.is_none());
        assert!(speedups(&runs, 100, 11).is_empty(), "another group's runs");
    }

    #[test]
    fn the_same_state_needs_every_run_of_the_group_to_end_in_the_checksum() {
        let mut runs = vec![run(1, 1, 1.0), run(2, 1, 0.5)];
        assert!(same_state(&runs, 100, 10, "ab"));
        runs[1].checksum = "cd".into();
        assert!(!same_state(&runs, 100, 10, "ab"));
    }
}
