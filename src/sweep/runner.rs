//! Running cells: warm-ups, timed trials, the checksum guard, progress and Ctrl-C.
//!
//! Each run simulates the whole dam break from the group's initial state on a fresh
//! [`Simulation`](crate::solver::Simulation), through [`run_timed`] (the timed region is the step loop only). Every run —
//! warm-up or trial — must end with the group's reference checksum, the one the group's
//! `seq` cell produced first; the first run that does not, or that fails, ends the cell as
//! failed with the reason, and the sweep goes on. A group whose `seq` cell failed has no
//! reference: its other cells are written as failed without running.
//!
//! Ctrl-C sets a flag that is checked before every run: the cell in progress is discarded
//! (nothing of it has been written), finished cells stay, and the sweep stops with an error
//! naming `--resume`. A second Ctrl-C exits at once.

use std::collections::HashMap;
use std::fmt;
use std::io::Write;
use std::sync::atomic::{AtomicBool, Ordering};

use anyhow::Context;
use indicatif::ProgressBar;

use super::console;
use super::export::Exporter;
use super::plan::{Cell, Group, Plan};
use super::rows::{CellContext, Measured, summary_row, trial_rows};
use super::timing::{Timing, Trial};
use crate::checksum::checksum_hex;
use crate::contention::Threshold;
use crate::results::rows::{Status, SummaryRow};
use crate::run::run_timed;
use crate::scene::Scene;

/// Set by Ctrl-C; checked before every run and every cell.
static INTERRUPTED: AtomicBool = AtomicBool::new(false);

/// Whether the sweep must stop: Ctrl-C was pressed, or standard output was closed (the
/// reader of `bench-sph sweep | head` went away), which ends the sweep the same way.
pub fn interrupted() -> bool {
    INTERRUPTED.load(Ordering::SeqCst) || crate::output::console::closed()
}

/// Makes Ctrl-C stop the sweep between runs (a second Ctrl-C exits at once). Harmless to
/// call twice: a process has one handler.
pub fn install_ctrlc_handler() {
    let _ = ctrlc::set_handler(|| {
        if INTERRUPTED.swap(true, Ordering::SeqCst) {
            crate::output::console::warn("\nCtrl-C again: quitting now; finished cells are saved");
            std::process::exit(130);
        }
        crate::output::console::warn(
            "\nCtrl-C: stopping after the current run; the cell in progress is discarded \
             (Ctrl-C again to quit at once)",
        );
    });
}

/// Which run of a cell.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RunKind {
    /// Untimed warm-up number k (from 1).
    Warmup(usize),
    /// Timed trial number k (from 1).
    Trial(usize),
}

impl fmt::Display for RunKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            RunKind::Warmup(k) => write!(f, "warm-up {k}"),
            RunKind::Trial(k) => write!(f, "trial {k}"),
        }
    }
}

/// How a cell's runs ended.
#[derive(Debug, Clone, PartialEq)]
pub enum CellOutcome {
    /// All runs done, or stopped at the first failure (`failure` says which and why).
    Finished {
        /// The timed trials that completed.
        measured: Vec<Measured>,
        /// Why the cell failed, if it did.
        failure: Option<String>,
    },
    /// Stopped by Ctrl-C between runs: nothing of the cell is kept.
    Interrupted,
}

/// Runs a cell's `warmup` warm-ups, then its `trials` trials, with `run`, checking each
/// run's checksum against `reference` (`None` for a `seq` reference cell: its first run sets
/// it). `stop` is asked before every run.
pub fn measure_cell(
    warmup: usize,
    trials: usize,
    reference: Option<&str>,
    stop: &dyn Fn() -> bool,
    mut run: impl FnMut(RunKind) -> Result<Measured, String>,
) -> CellOutcome {
    let mut expected = reference.map(str::to_owned);
    let mut measured = Vec::with_capacity(trials);
    let kinds = (1..=warmup)
        .map(RunKind::Warmup)
        .chain((1..=trials).map(RunKind::Trial));
    for kind in kinds {
        if stop() {
            return CellOutcome::Interrupted;
        }
        let m = match run(kind) {
            Ok(m) => m,
            Err(e) => {
                return CellOutcome::Finished {
                    measured,
                    failure: Some(format!("{kind}: {e}")),
                };
            }
        };
        let mismatch = match &expected {
            None => {
                expected = Some(m.checksum.clone());
                None
            }
            Some(want) if *want != m.checksum => Some(format!(
                "{kind}: checksum {} differs from the reference {want} of seq at 1 core",
                m.checksum
            )),
            Some(_) => None,
        };
        if let RunKind::Trial(_) = kind {
            measured.push(m);
        }
        if mismatch.is_some() {
            return CellOutcome::Finished {
                measured,
                failure: mismatch,
            };
        }
    }
    CellOutcome::Finished {
        measured,
        failure: None,
    }
}

/// What a group's other cells are measured against.
#[derive(Debug, Clone, PartialEq)]
pub enum Reference {
    /// The `seq` cell succeeded: its checksum and trial wall seconds.
    Ok {
        /// The checksum every run must reproduce.
        checksum: String,
        /// The wall seconds of its trials (their mean is the denominator of speedup).
        walls: Vec<f64>,
    },
    /// The `seq` cell failed for this reason.
    Failed(String),
}

impl Reference {
    /// The reference a finished `seq` cell gives: its summary row and its trial wall seconds.
    pub fn from_row(row: &SummaryRow, walls: Vec<f64>) -> Reference {
        match (row.status, row.mean_s) {
            (Status::Ok, Some(_)) if !walls.is_empty() => Reference::Ok {
                checksum: row.checksum.clone(),
                walls,
            },
            (Status::Ok, _) => Reference::Failed("its trials are missing".to_owned()),
            _ => Reference::Failed(row.reason.clone()),
        }
    }
}

/// The initial state of a group, built once and cloned for every run.
struct GroupInput {
    group: Group,
    scene: Scene,
}

impl GroupInput {
    fn new(group: Group, seed: u64) -> GroupInput {
        let scene = Scene::dam_break(group.preset, group.n, seed)
            .unwrap_or_else(|e| panic!("no memory for {} particles: {e}", group.n));
        GroupInput { group, scene }
    }

    /// One whole run of `cell` from the initial state: its times and final checksum.
    fn run(&self, cell: &Cell) -> Result<Measured, String> {
        self.run_steps(cell, self.group.steps)
    }

    /// `steps` steps of `cell` from the initial state.
    fn run_steps(&self, cell: &Cell, steps: usize) -> Result<Measured, String> {
        let mut sim = self.scene.clone().simulate(self.group.neighbors);
        let load1 = crate::contention::load1();
        let placement =
            crate::placement::placement(cell.pin).map_err(|e| one_line(&format!("{e:#}")))?;
        let config = cell.config().placed(placement);
        let elapsed = run_timed(&mut sim, cell.strategy, &config, steps)
            .map_err(|e| one_line(&format!("{:#}", anyhow::Error::new(e))))?;
        Ok(Measured {
            elapsed,
            load1,
            checksum: checksum_hex(&sim.state),
        })
    }
}

/// A message on one line (CSV fields and resume's line-based repair rely on it).
fn one_line(s: &str) -> String {
    s.split_whitespace().collect::<Vec<_>>().join(" ")
}

/// The most particles the estimate simulates, per neighbour search: it must take well under
/// a second whatever N the sweep asks for.
const CALIBRATION_N_ALL_PAIRS: usize = 4000;
/// See [`CALIBRATION_N_ALL_PAIRS`].
const CALIBRATION_N_GRID: usize = 200_000;

/// Seconds one `seq` run of `group` takes, estimated from a short timed run of at most
/// 4000 (all-pairs, `CALIBRATION_N_ALL_PAIRS`) or 200 000 (grid, `CALIBRATION_N_GRID`) particles,
/// scaled by (N / sample)² or N / sample: one step, then doubling the steps until a run
/// takes 50 ms or covers all steps. NaN when the run fails (the sweep will then report the
/// failure properly).
pub fn calibrate(group: Group, seed: u64) -> f64 {
    let (cap, exponent) = match group.neighbors {
        crate::sph::neighbors::NeighborMode::AllPairs => (CALIBRATION_N_ALL_PAIRS, 2),
        crate::sph::neighbors::NeighborMode::Grid => (CALIBRATION_N_GRID, 1),
    };
    let sample = Group {
        n: group.n.min(cap),
        ..group
    };
    let scale = (group.n as f64 / sample.n as f64).powi(exponent);
    let input = GroupInput::new(sample, seed);
    let seq = Cell::reference(sample);
    let mut steps = 1;
    loop {
        let Ok(m) = input.run_steps(&seq, steps) else {
            return f64::NAN;
        };
        if m.elapsed.wall_s >= 0.05 || steps >= group.steps {
            return m.elapsed.wall_s / steps as f64 * group.steps as f64 * scale;
        }
        steps = (steps * 2).min(group.steps);
    }
}

/// Everything a session needs to run cells.
pub struct Runner<'a, T: Write, S: Write> {
    /// The plan (cells are named by their position in it).
    pub plan: &'a Plan,
    /// Warm-ups per cell.
    pub warmup: usize,
    /// Trials per cell.
    pub trials: usize,
    /// Seed of the initial states and of the bootstrap.
    pub seed: u64,
    /// Bootstrap resamples per interval.
    pub resamples: usize,
    /// The machine's hardware threads (for `oversubscribed` and contention).
    pub hardware_threads: usize,
    /// When foreign CPU makes a trial contended.
    pub threshold: Threshold,
    /// Where trial numbers come from.
    pub timing: Timing,
    /// Test only: behave as if Ctrl-C was pressed after this many cells.
    pub stop_after_cells: Option<usize>,
    /// The CSV writers.
    pub exporter: Exporter<T, S>,
    /// The progress bar, in estimated milliseconds.
    pub progress: ProgressBar,
    /// Estimated milliseconds of one run of each cell of the plan.
    pub run_ms: Vec<u64>,
    /// The shard of the plan this sweep runs (`reference_shard` of its rows), if it is one.
    pub shard: Option<usize>,
}

/// What a session did.
#[derive(Debug, Default)]
pub struct SessionOutcome {
    /// The summary rows written, in order.
    pub rows: Vec<SummaryRow>,
    /// Whether it stopped early (Ctrl-C or `--stop-after-cells`).
    pub interrupted: bool,
}

/// What `cell` is measured against: the checksum its runs must reproduce and the group's
/// `seq` walls (both `None` for the reference cell itself), or why it cannot run.
type Against = (Option<String>, Option<String>, Option<Vec<f64>>);

/// The group's reference as `cell` needs it (see [`Against`]): `(checksum, failure, walls)`.
fn against(cell: &Cell, references: &HashMap<Group, Reference>) -> Against {
    if cell.is_reference() {
        return (None, None, None);
    }
    match references.get(&cell.group) {
        Some(Reference::Ok { checksum, walls }) => {
            (Some(checksum.clone()), None, Some(walls.clone()))
        }
        Some(Reference::Failed(why)) => (
            None,
            Some(format!("not run: the group's seq reference failed ({why})")),
            None,
        ),
        None => (
            None,
            Some("not run: the group has no seq reference".to_owned()),
            None,
        ),
    }
}

impl<T: Write, S: Write> Runner<'_, T, S> {
    /// Runs the cells at positions `todo` of the plan (ascending), measuring each against its
    /// group's entry in `references` (filled in as `seq` cells finish), and writes each
    /// finished cell at once.
    pub fn run(
        &mut self,
        todo: &[usize],
        references: &mut HashMap<Group, Reference>,
    ) -> anyhow::Result<SessionOutcome> {
        let mut outcome = SessionOutcome::default();
        let mut input: Option<GroupInput> = None;
        let mut shown_group: Option<Group> = None;
        for &index in todo {
            let stop_now = self.stop_after_cells == Some(outcome.rows.len());
            if interrupted() || stop_now {
                outcome.interrupted = true;
                break;
            }
            let cell = self.plan.cells[index];
            let (measured, failure, seq_walls) = against(&cell, references);
            let (measured, failure) = if let Some(failure) = failure {
                self.progress
                    .inc(self.run_ms[index].saturating_mul((self.warmup + self.trials) as u64));
                (Vec::new(), Some(failure))
            } else {
                if input.as_ref().is_none_or(|i| i.group != cell.group) {
                    input = Some(GroupInput::new(cell.group, self.seed));
                }
                let group_input = input.as_ref().expect("built above");
                self.progress.set_message(cell.label());
                match self.measure(index, &cell, group_input, measured.as_deref()) {
                    CellOutcome::Interrupted => {
                        outcome.interrupted = true;
                        break;
                    }
                    CellOutcome::Finished { measured, failure } => (measured, failure),
                }
            };

            let summary = self.record(index, &measured, failure, seq_walls, references)?;
            let mut text = String::new();
            if self.plan.groups.len() > 1 && shown_group != Some(cell.group) {
                text = format!("{}:\n", cell.group.label(super::plan::LabelStyle::Sweep));
                shown_group = Some(cell.group);
            }
            text.push_str(&console::cell_line(
                index + 1,
                self.plan.cells.len(),
                &cell,
                &summary,
            ));
            // A closed standard output ends the sweep like Ctrl-C (checked before the next
            // cell); this cell is written already.
            self.progress.suspend(|| {
                let _ = crate::output::console::line(&text);
            });
            outcome.rows.push(summary);
        }
        Ok(outcome)
    }

    /// Writes the cell at `index` of the plan (its trial rows and summary row, against the
    /// group's `seq` walls), and records a reference cell in `references`.
    fn record(
        &mut self,
        index: usize,
        measured: &[Measured],
        failure: Option<String>,
        seq_walls: Option<Vec<f64>>,
        references: &mut HashMap<Group, Reference>,
    ) -> anyhow::Result<SummaryRow> {
        let cell = self.plan.cells[index];
        let seq_walls = if cell.is_reference() {
            failure.is_none().then(|| walls(measured))
        } else {
            seq_walls
        };
        let ctx = CellContext {
            seq_walls: seq_walls.as_deref(),
            hardware_threads: self.hardware_threads,
            threshold: self.threshold,
            seed: self.seed,
            resamples: self.resamples,
            shard: self.shard,
            smt: crate::placement::machine_topology().is_smt(cell.cores),
        };
        let summary = summary_row(&cell, measured, failure.as_deref(), &ctx);
        let trials = trial_rows(&cell, measured, failure.as_deref());
        self.exporter
            .write_cell(&trials, &summary)
            .context("cannot write the results")?;
        if cell.is_reference() {
            references.insert(cell.group, Reference::from_row(&summary, walls(measured)));
        }
        Ok(summary)
    }

    /// The runs of one cell, with the progress bar advanced after each.
    fn measure(
        &self,
        index: usize,
        cell: &Cell,
        input: &GroupInput,
        reference: Option<&str>,
    ) -> CellOutcome {
        let run_ms = self.run_ms[index];
        measure_cell(self.warmup, self.trials, reference, &interrupted, |kind| {
            let result = input.run(cell);
            self.progress.inc(run_ms);
            let mut m = result?;
            if let RunKind::Trial(k) = kind {
                let measured = Trial {
                    elapsed: m.elapsed,
                    load1: m.load1,
                };
                let t =
                    self.timing
                        .trial(measured, index, self.trials, k - 1, self.hardware_threads);
                (m.elapsed, m.load1) = (t.elapsed, t.load1);
            }
            Ok(m)
        })
    }
}

fn walls(measured: &[Measured]) -> Vec<f64> {
    measured.iter().map(|m| m.elapsed.wall_s).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::clock::Elapsed;
    use sph_strategies::StrategyName;
    use std::cell::Cell as Counter;

    fn ok(checksum: &str) -> Result<Measured, String> {
        Ok(Measured {
            elapsed: Elapsed {
                wall_s: 1.0,
                cpu_s: 1.0,
                foreign: None,
            },
            load1: None,
            checksum: checksum.to_owned(),
        })
    }

    fn never() -> bool {
        false
    }

    #[test]
    fn a_cell_runs_its_warmups_then_its_trials_and_keeps_only_the_trials() {
        let mut kinds = Vec::new();
        let out = measure_cell(2, 3, Some("a"), &never, |k| {
            kinds.push(k);
            ok("a")
        });
        use RunKind::*;
        assert_eq!(kinds, [Warmup(1), Warmup(2), Trial(1), Trial(2), Trial(3)]);
        let CellOutcome::Finished { measured, failure } = out else {
            panic!("interrupted")
        };
        assert_eq!((measured.len(), failure), (3, None));
    }

    #[test]
    fn a_checksum_that_differs_from_the_reference_fails_the_cell() {
        let calls = Counter::new(0);
        let out = measure_cell(1, 3, Some("a"), &never, |_| {
            calls.set(calls.get() + 1);
            if calls.get() == 3 { ok("b") } else { ok("a") }
        });
        let CellOutcome::Finished { measured, failure } = out else {
            panic!("interrupted")
        };
        assert_eq!(measured.len(), 2, "the mismatching trial is kept as a row");
        let failure = failure.unwrap();
        assert!(
            failure.starts_with("trial 2: checksum b differs from the reference a"),
            "{failure}"
        );
        assert_eq!(calls.get(), 3, "the cell stops at its first failure");
    }

    #[test]
    fn a_mismatch_in_a_warmup_also_fails_the_cell() {
        let out = measure_cell(1, 2, Some("a"), &never, |_| ok("b"));
        let CellOutcome::Finished { measured, failure } = out else {
            panic!("interrupted")
        };
        assert!(measured.is_empty());
        assert!(failure.unwrap().starts_with("warm-up 1: checksum b"));
    }

    #[test]
    fn the_reference_cell_sets_the_checksum_with_its_first_run_and_must_repeat_it() {
        let calls = Counter::new(0);
        let out = measure_cell(1, 2, None, &never, |_| {
            calls.set(calls.get() + 1);
            ok(if calls.get() == 1 { "a" } else { "c" })
        });
        let CellOutcome::Finished { failure, .. } = out else {
            panic!("interrupted")
        };
        assert!(
            failure
                .unwrap()
                .contains("checksum c differs from the reference a")
        );
    }

    #[test]
    fn a_run_error_fails_the_cell_with_its_reason() {
        let out = measure_cell(0, 2, Some("a"), &never, |k| match k {
            RunKind::Trial(2) => Err("the simulation diverged at step 3".to_owned()),
            _ => ok("a"),
        });
        let CellOutcome::Finished { measured, failure } = out else {
            panic!("interrupted")
        };
        assert_eq!(measured.len(), 1);
        assert_eq!(
            failure.unwrap(),
            "trial 2: the simulation diverged at step 3"
        );
    }

    #[test]
    fn a_stop_request_between_runs_discards_the_cell() {
        let calls = Counter::new(0);
        let stop = || calls.get() >= 2;
        let out = measure_cell(1, 3, Some("a"), &stop, |_| {
            calls.set(calls.get() + 1);
            ok("a")
        });
        assert_eq!(out, CellOutcome::Interrupted);
        assert_eq!(calls.get(), 2);
    }

    #[test]
    fn a_real_run_reproduces_the_sequential_checksum_on_every_strategy() {
        let group = Group {
            preset: crate::sph::params::Preset::Seed,
            neighbors: crate::sph::neighbors::NeighborMode::Grid,
            n: 50,
            steps: 4,
        };
        let input = GroupInput::new(group, 3);
        let checksums: Vec<String> = StrategyName::ALL
            .iter()
            .map(|&strategy| {
                let cell = Cell {
                    group,
                    strategy,
                    cores: 2,
                    chunks: Some(3),
                    pin: crate::topology::Pin::None,
                };
                input.run(&cell).unwrap().checksum
            })
            .collect();
        assert!(
            checksums.iter().all(|c| *c == checksums[0]),
            "{checksums:?}"
        );
        assert!(calibrate(group, 3) > 0.0);
    }
}
