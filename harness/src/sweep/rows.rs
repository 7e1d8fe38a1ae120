//! How a run's measurement becomes its row of `trials.csv` ([`crate::results::rows`]); the
//! summary rows are computed from the trial rows ([`crate::results::summarize`]).

use super::schedule::Run;
use super::windows::Verdict;
use crate::clock::Elapsed;
use crate::results::key::Cell;
use crate::results::rows::{Phase, Status, TrialRow};

/// One timed run: its times and the checksum of its final state.
#[derive(Debug, Clone, PartialEq)]
pub struct Measured {
    /// Wall, CPU and foreign CPU seconds of the step loop.
    pub elapsed: Elapsed,
    /// The 1-minute load average when the run started (`None` where unknown).
    pub load1: Option<f64>,
    /// [`sph_solver::checksum::checksum_hex`] of the final state.
    pub checksum: String,
}

/// The trial row of `run` of `cell` in `phase`: trial number `trial` (from 1) of the cell in
/// the phase, `failure` the reason when this run failed the cell, `verdict` its contention
/// window's.
pub fn trial_row(
    cell: &Cell,
    phase: Phase,
    run: &Run,
    trial: usize,
    m: &Measured,
    failure: Option<&str>,
    verdict: Verdict,
) -> TrialRow {
    TrialRow {
        strategy: cell.strategy,
        neighbors: cell.group.neighbors,
        preset: cell.group.preset,
        n: cell.group.n,
        steps: cell.group.steps,
        cores: cell.cores,
        chunks: cell.chunks,
        particles_per_chunk: cell.particles_per_chunk(),
        trial,
        wall_s: m.elapsed.wall_s,
        cpu_s: m.elapsed.cpu_s,
        checksum: m.checksum.clone(),
        status: if failure.is_some() {
            Status::Failed
        } else {
            Status::Ok
        },
        reason: failure.unwrap_or_default().to_owned(),
        foreign_cpu_s: m.elapsed.foreign.map(|f| f.cpu_s),
        steal_s: m.elapsed.foreign.and_then(|f| f.steal_s),
        load1: m.load1,
        pin: cell.pin,
        phase,
        round: Some(run.round),
        position: Some(run.position),
        window_foreign_threads: verdict.foreign_threads,
        contended: verdict.contended,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contention::Foreign;
    use crate::results::key::test_group;
    use sph_solver::sph::neighbors::NeighborMode;
    use sph_strategies::StrategyName;

    #[test]
    fn a_trial_row_carries_the_run_its_window_and_its_cell() {
        let cell = Cell {
            group: test_group(NeighborMode::Grid),
            strategy: StrategyName::CrossbeamPool,
            cores: 2,
            chunks: Some(5),
            pin: crate::topology::Pin::None,
        };
        let m = Measured {
            elapsed: Elapsed {
                wall_s: 0.5,
                cpu_s: 1.0,
                foreign: Some(Foreign {
                    cpu_s: 0.01,
                    steal_s: None,
                }),
            },
            load1: Some(0.2),
            checksum: "00000000000000aa".to_owned(),
        };
        let run = Run {
            cell: 3,
            round: 4,
            position: 2,
        };
        let verdict = Verdict {
            foreign_threads: Some(0.9),
            contended: Some(true),
        };
        let row = trial_row(&cell, Phase::Confirm, &run, 4, &m, None, verdict);
        assert_eq!(row.key(), cell);
        assert_eq!((row.trial, row.round, row.position), (4, Some(4), Some(2)));
        assert_eq!(
            (row.wall_s, row.cpu_s, row.foreign_cpu_s),
            (0.5, 1.0, Some(0.01))
        );
        assert_eq!(
            (row.window_foreign_threads, row.contended),
            (Some(0.9), Some(true))
        );
        assert_eq!((row.phase, row.status), (Phase::Confirm, Status::Ok));
        assert_eq!(row.particles_per_chunk, Some(12));
        let failed = trial_row(&cell, Phase::Grid, &run, 4, &m, Some("boom"), verdict);
        assert_eq!(
            (failed.status, failed.reason.as_str()),
            (Status::Failed, "boom")
        );
    }
}
