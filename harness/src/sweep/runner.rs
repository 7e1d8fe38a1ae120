//! Running a group's phases: the reference run, the rounds ([`super::schedule`]), the
//! checksum guard, contention windows ([`super::windows`]), the wait for a quiet machine,
//! progress and Ctrl-C.
//!
//! A group runs its grid phase (every cell of the plan, `--trials` rounds), then, unless the
//! sweep is a shard or `--confirm-rounds 0`, its confirmation phase (the cells
//! [`super::confirm::choose`] picks from the grid's rows, `--confirm-rounds` rounds). Each
//! phase starts with the **reference run**: an untimed `seq` run whose checksum every later
//! run must reproduce (under `rounds` it is the group's warm-up too: `--warmup W` makes W such
//! runs, at least one). The first run that does not reproduce it, or that fails, ends its cell
//! as failed with the reason, and the phase goes on without it; when the `seq` cell itself
//! fails, the phase stops and its other cells are written as failed.
//!
//! A run's trial row is written (and flushed) when its contention window closes, about every
//! second; a phase's summary rows are written together once its last round is done. Ctrl-C,
//! SIGTERM or SIGHUP ([`crate::signals`]) sets a flag that is checked before every run: the
//! runs already measured are written, the run in progress is discarded, and the sweep stops
//! with an error naming `--resume`, which continues the round it was in. A second signal
//! exits at once.

use std::collections::{HashMap, HashSet};
use std::io::Write;
use std::time::{Duration, Instant};

use anyhow::Context;
use indicatif::ProgressBar;

use super::confirm;
use super::console;
use super::input::GroupInput;
use super::plan::{Cell, Group, Plan};
use super::rows::{Measured, trial_row};
use super::schedule::{self, Run, Schedule};
use super::timing::{Timing, Trial, fake_index};
use super::windows::{Verdict, Windows};
use crate::contention::Threshold;
use crate::results::export::Exporter;
use crate::results::params::SweepParams;
use crate::results::rows::{Phase, Status, SummaryRow, TrialRow};
use crate::results::summarize::{CellContext, summary_row};

/// Whether the sweep must stop, checked before every run and every cell: Ctrl-C, SIGTERM or
/// SIGHUP arrived ([`crate::signals`]), or standard output was closed (the reader of
/// `bench-sph sweep | head` went away), which ends the sweep the same way.
pub fn interrupted() -> bool {
    crate::signals::requested() || crate::output::console::closed()
}

/// What earlier sessions left of the sweep (from `--resume`'s repair).
#[derive(Debug, Clone, Default)]
pub struct Kept {
    /// Summary rows of finished cell phases.
    pub finished: Vec<SummaryRow>,
    /// Trial rows of phases not finished yet: runs not to repeat.
    pub pending: Vec<TrialRow>,
}

/// Everything a session needs to run cells.
pub struct Runner<'a, T: Write, S: Write> {
    /// The plan (cells are named by their position in it).
    pub plan: &'a Plan,
    /// The sweep's parameters: rounds, warm-ups, schedule, seed, wait.
    pub params: &'a SweepParams,
    /// The machine's hardware threads (for `oversubscribed` and contention).
    pub hardware_threads: usize,
    /// When foreign CPU makes a window contended.
    pub threshold: Threshold,
    /// Where run numbers come from.
    pub timing: Timing,
    /// Test only: behave as if Ctrl-C was pressed once this many runs are written.
    pub stop_after_runs: Option<usize>,
    /// Longest wait for a quiet machine before each round (zero: do not wait).
    pub wait_quiet: Duration,
    /// The CSV writers.
    pub exporter: Exporter<T, S>,
    /// The progress bar, in estimated milliseconds.
    pub progress: ProgressBar,
    /// Estimated milliseconds of one run of each cell of the plan.
    pub run_ms: Vec<u64>,
    /// Timed runs written by this session.
    pub runs_written: usize,
}

/// What a session did.
#[derive(Debug, Default)]
pub struct SessionOutcome {
    /// The summary rows written, in order.
    pub rows: Vec<SummaryRow>,
    /// Whether it stopped early (Ctrl-C or `--stop-after-runs`).
    pub interrupted: bool,
}

/// One phase of one group.
struct PhaseWork<'k> {
    group: Group,
    phase: Phase,
    /// Plan positions, the group's `seq` first.
    cells: Vec<usize>,
    rounds: usize,
    /// Summary rows of this phase finished by earlier sessions, by plan position.
    finished: HashMap<usize, &'k SummaryRow>,
    /// Runs of this phase earlier sessions measured.
    pending: Vec<&'k TrialRow>,
}

/// The state of a phase while it runs.
struct Progress {
    /// Each cell's trial rows so far (kept and new), by plan position.
    rows_of: HashMap<usize, Vec<TrialRow>>,
    /// Cells that failed, with why.
    failed: HashMap<usize, String>,
    /// Runs measured, waiting for their contention window to close: plan position and row.
    buffered: Vec<(usize, TrialRow)>,
    /// The checksum every run must reproduce.
    reference: Option<String>,
}

impl Progress {
    fn trial_number(&self, cell: usize) -> usize {
        let written = self.rows_of.get(&cell).map_or(0, Vec::len);
        let waiting = self.buffered.iter().filter(|(c, _)| *c == cell).count();
        written + waiting + 1
    }
}

impl<T: Write, S: Write> Runner<'_, T, S> {
    /// Runs every group's phases that `kept` does not hold finished, group after group, and
    /// writes their rows.
    pub fn run(&mut self, kept: &Kept) -> anyhow::Result<SessionOutcome> {
        let mut outcome = SessionOutcome::default();
        for &group in &self.plan.groups {
            let cells: Vec<usize> = (0..self.plan.cells.len())
                .filter(|&i| self.plan.cells[i].group == group)
                .collect();
            let grid = self.work(group, Phase::Grid, cells, self.params.trials, kept);
            let Some(grid_rows) = self.phase(&grid, &mut outcome)? else {
                outcome.interrupted = true;
                break;
            };
            if self.params.confirm_rounds == 0 || self.params.shard.is_some() {
                continue;
            }
            let chosen: Vec<usize> = confirm::choose(self.plan, &group, &grid_rows)
                .into_iter()
                .map(|(at, _)| at)
                .collect();
            if chosen.len() < 2 {
                continue;
            }
            let confirm = self.work(
                group,
                Phase::Confirm,
                chosen,
                self.params.confirm_rounds,
                kept,
            );
            if self.phase(&confirm, &mut outcome)?.is_none() {
                outcome.interrupted = true;
                break;
            }
        }
        Ok(outcome)
    }

    /// The work of `group`'s `phase` over `cells`, with what `kept` holds of it.
    fn work<'k>(
        &self,
        group: Group,
        phase: Phase,
        cells: Vec<usize>,
        rounds: usize,
        kept: &'k Kept,
    ) -> PhaseWork<'k> {
        let position = |cell: Cell| self.plan.cells.iter().position(|c| *c == cell);
        let finished = kept
            .finished
            .iter()
            .filter(|r| r.phase == phase)
            .filter_map(|r| Some((position(r.key())?, r)))
            .filter(|(at, _)| cells.contains(at))
            .collect();
        let pending = kept
            .pending
            .iter()
            .filter(|r| r.phase == phase && position(r.key()).is_some_and(|at| cells.contains(&at)))
            .collect();
        PhaseWork {
            group,
            phase,
            cells,
            rounds,
            finished,
            pending,
        }
    }

    /// Runs a phase; returns all its summary rows (kept and new), or `None` when the sweep
    /// was interrupted in it.
    fn phase(
        &mut self,
        work: &PhaseWork<'_>,
        outcome: &mut SessionOutcome,
    ) -> anyhow::Result<Option<Vec<SummaryRow>>> {
        let mut rows: Vec<SummaryRow> = work.finished.values().map(|r| (*r).clone()).collect();
        if work.cells.iter().all(|c| work.finished.contains_key(c)) {
            return Ok(Some(rows));
        }
        let seq = work.cells[0];
        let mut state = Progress {
            rows_of: HashMap::new(),
            failed: HashMap::new(),
            buffered: Vec::new(),
            reference: None,
        };
        let mut done: HashSet<(usize, usize)> = HashSet::new();
        for &row in &work.pending {
            let at = self.position(row);
            done.insert((at, row.round.unwrap_or(row.trial)));
            if row.status == Status::Failed {
                state.failed.insert(at, row.reason.clone());
            }
            state.rows_of.entry(at).or_default().push(row.clone());
        }
        let runs = schedule::order(
            self.params.schedule,
            &work.cells,
            work.rounds,
            self.params.seed,
            &work.group,
            work.phase,
        );
        let todo: Vec<Run> = runs
            .into_iter()
            .filter(|r| !work.finished.contains_key(&r.cell) && !done.contains(&(r.cell, r.round)))
            .collect();
        let input = GroupInput::new(work.group, self.params.seed);
        let mut windows = Windows::new(self.threshold, self.timing.fakes_contention());
        let interrupted = self.measure(work, &todo, &input, &mut state, &mut windows)?;
        self.write_verdicts(&mut state, windows.close())?;
        if interrupted {
            return Ok(None);
        }
        let new_rows = self.summaries(work, seq, &mut state);
        self.exporter
            .write_summaries(&new_rows)
            .context("cannot write the results")?;
        self.print_phase(work, &new_rows);
        rows.extend(new_rows.iter().cloned());
        outcome.rows.extend(new_rows);
        Ok(Some(rows))
    }

    /// The plan position of a row's cell (the caller made sure it is in the plan).
    fn position(&self, row: &TrialRow) -> usize {
        self.plan
            .cells
            .iter()
            .position(|c| *c == row.key())
            .expect("kept rows are of the plan's cells")
    }

    /// Runs `todo` in order (the reference run first); returns whether the sweep was
    /// interrupted.
    fn measure(
        &mut self,
        work: &PhaseWork<'_>,
        todo: &[Run],
        input: &GroupInput,
        state: &mut Progress,
        windows: &mut Windows<usize>,
    ) -> anyhow::Result<bool> {
        if todo.is_empty() {
            return Ok(false);
        }
        let seq = work.cells[0];
        let widest = work
            .cells
            .iter()
            .map(|&c| self.plan.cells[c].cores)
            .max()
            .unwrap_or(1);
        self.wait_quiet(work, widest, windows, state)?;
        let reference_runs = match self.params.schedule {
            Schedule::Rounds => self.params.warmup.max(1),
            Schedule::Cells => 1,
        };
        self.untimed(input, seq, reference_runs, state);
        let mut round = todo[0].round;
        let mut warmed: HashSet<usize> = HashSet::new();
        for run in todo {
            if state.failed.contains_key(&seq) {
                break;
            }
            if state.failed.contains_key(&run.cell) {
                continue;
            }
            if run.round != round && self.params.schedule == Schedule::Rounds {
                round = run.round;
                if self.wait_quiet(work, widest, windows, state)? {
                    self.untimed(input, seq, 1, state);
                }
            }
            if self.params.schedule == Schedule::Cells && warmed.insert(run.cell) {
                self.untimed(input, run.cell, self.params.warmup, state);
                if state.failed.contains_key(&run.cell) {
                    continue;
                }
            }
            if self.stop() {
                return Ok(true);
            }
            self.timed(work, run, input, state, windows)?;
        }
        Ok(false)
    }

    /// `count` untimed runs of the cell at `at`; the first run of a phase sets the reference
    /// checksum (and must agree with the runs kept from earlier sessions).
    fn untimed(&mut self, input: &GroupInput, at: usize, count: usize, state: &mut Progress) {
        let cell = self.plan.cells[at];
        for k in 1..=count {
            if self.stop() {
                return;
            }
            let result = input.run(&cell);
            self.progress.inc(self.run_ms[at]);
            let failure = match result {
                Err(e) => Some(format!("warm-up {k}: {e}")),
                Ok(m) => self.check(
                    &mut state.reference,
                    &m.checksum,
                    &format!("warm-up {k}"),
                    state.rows_of.values().flatten(),
                ),
            };
            if let Some(why) = failure {
                state.failed.insert(at, why);
                return;
            }
        }
    }

    /// The failure, if any, of a run named `what` that ended with `checksum`, against the
    /// phase's reference (set by the first run checked, which must agree with `kept`'s ok
    /// runs).
    fn check<'r>(
        &self,
        reference: &mut Option<String>,
        checksum: &str,
        what: &str,
        kept: impl IntoIterator<Item = &'r TrialRow>,
    ) -> Option<String> {
        match reference {
            Some(want) if want != checksum => Some(format!(
                "{what}: checksum {checksum} differs from the reference {want} of seq at 1 core"
            )),
            Some(_) => None,
            None => {
                let earlier = kept
                    .into_iter()
                    .find(|r| r.status == Status::Ok && r.checksum != checksum);
                *reference = Some(checksum.to_owned());
                earlier.map(|r| {
                    format!(
                        "{what}: the reference checksum {checksum} differs from {} of the runs \
                         kept from an earlier session: this build computes other bits; resume \
                         with the build that started the sweep, or start a new one",
                        r.checksum
                    )
                })
            }
        }
    }

    /// One timed run: measured, checked, buffered until its window closes.
    fn timed(
        &mut self,
        work: &PhaseWork<'_>,
        run: &Run,
        input: &GroupInput,
        state: &mut Progress,
        windows: &mut Windows<usize>,
    ) -> anyhow::Result<()> {
        let cell = self.plan.cells[run.cell];
        self.progress
            .set_message(format!("round {} · {}", run.round, cell.label()));
        windows.before_run();
        let result = input.run(&cell);
        self.progress.inc(self.run_ms[run.cell]);
        let what = format!("round {}", run.round);
        let m = match result {
            Ok(m) => self.faked(work.phase, run, m),
            Err(e) => {
                state.failed.insert(run.cell, format!("{what}: {e}"));
                return Ok(());
            }
        };
        let failure = self.check(&mut state.reference, &m.checksum, &what, std::iter::empty());
        let unknown = Verdict {
            foreign_threads: None,
            contended: None,
        };
        let trial = state.trial_number(run.cell);
        let row = trial_row(
            &cell,
            work.phase,
            run,
            trial,
            &m,
            failure.as_deref(),
            unknown,
        );
        if let Some(why) = failure {
            state.failed.insert(run.cell, why);
        }
        let key = state.buffered.len();
        state.buffered.push((run.cell, row));
        let fake = self
            .timing
            .fakes_contention()
            .then(|| (m.elapsed.foreign.map_or(0.0, |f| f.cpu_s), m.elapsed.wall_s));
        let verdicts = windows.after_run(key, cell.cores, fake);
        self.write_verdicts(state, verdicts)
    }

    /// `m` with the fake numbers of `--fake-timings` / `--fake-contention` where given.
    fn faked(&self, phase: Phase, run: &Run, mut m: Measured) -> Measured {
        let index = fake_index(
            phase,
            run.cell,
            run.round,
            self.plan.cells.len(),
            self.params.trials,
            self.params.confirm_rounds,
        );
        let t = self.timing.trial(
            Trial {
                elapsed: m.elapsed,
                load1: m.load1,
            },
            index,
            self.hardware_threads,
        );
        (m.elapsed, m.load1) = (t.elapsed, t.load1);
        m
    }

    /// Writes the buffered rows whose window closed, with its verdicts.
    fn write_verdicts(
        &mut self,
        state: &mut Progress,
        verdicts: Vec<(usize, Verdict)>,
    ) -> anyhow::Result<()> {
        if verdicts.is_empty() {
            return Ok(());
        }
        let mut rows = std::mem::take(&mut state.buffered);
        for (key, verdict) in verdicts {
            let row = &mut rows[key].1;
            row.window_foreign_threads = verdict.foreign_threads;
            row.contended = verdict.contended;
        }
        let trial_rows: Vec<TrialRow> = rows.iter().map(|(_, r)| r.clone()).collect();
        self.exporter
            .write_trials(&trial_rows)
            .context("cannot write the results")?;
        self.runs_written += rows.len();
        for (at, row) in rows {
            state.rows_of.entry(at).or_default().push(row);
        }
        Ok(())
    }

    /// Whether to stop before the next run.
    fn stop(&self) -> bool {
        interrupted() || self.stop_after_runs.is_some_and(|k| self.runs_written >= k)
    }

    /// With `--wait-quiet`, waits (bounded, and saying so) until other work leaves the
    /// machine quiet enough for a cell of `widest` cores. Returns whether it waited (the
    /// caller then warms up again: an idle core slows down).
    fn wait_quiet(
        &mut self,
        work: &PhaseWork<'_>,
        widest: usize,
        windows: &mut Windows<usize>,
        state: &mut Progress,
    ) -> anyhow::Result<bool> {
        if self.wait_quiet.is_zero() {
            return Ok(false);
        }
        // The wait belongs to no run's window.
        self.write_verdicts(state, windows.close())?;
        let bound = self.wait_quiet;
        let start = Instant::now();
        let mut busy = self.busy_threads(Duration::from_millis(300));
        if !self.too_busy(busy, widest) {
            return Ok(false);
        }
        let label = format!(
            "{} ({})",
            work.group.label(super::plan::LabelStyle::Sweep),
            work.phase.as_str()
        );
        self.progress.suspend(|| {
            console::waiting(&label, busy, self.hardware_threads, bound);
        });
        while self.too_busy(busy, widest) && start.elapsed() < bound && !self.stop() {
            busy = self
                .busy_threads(Duration::from_secs(1).min(bound.saturating_sub(start.elapsed())));
        }
        let quiet = !self.too_busy(busy, widest);
        self.progress.suspend(|| {
            console::waited(quiet, start.elapsed(), busy);
        });
        Ok(true)
    }

    /// Hardware threads' worth of CPU other work used over `window` (fake with
    /// `--fake-contention`); `None` where the machine cannot say.
    fn busy_threads(&self, window: Duration) -> Option<f64> {
        if let Some(threads) = self.timing.fake_busy_threads(self.hardware_threads) {
            std::thread::sleep(window.min(Duration::from_millis(50)));
            return Some(threads);
        }
        let (foreign_s, wall_s) = crate::clock::sample_now(window)?;
        Some(foreign_s / wall_s)
    }

    fn too_busy(&self, busy: Option<f64>, cores: usize) -> bool {
        busy.is_some_and(|b| self.threshold.exceeded(b, 1.0, cores))
    }

    /// The summary rows of the phase's cells that earlier sessions did not finish.
    fn summaries(&self, work: &PhaseWork<'_>, seq: usize, state: &mut Progress) -> Vec<SummaryRow> {
        let seq_failed = state.failed.get(&seq).cloned();
        let mut seq_rows = state.rows_of.get(&seq).cloned().unwrap_or_default();
        seq_rows.sort_by_key(|t| t.trial);
        work.cells
            .iter()
            .filter(|at| !work.finished.contains_key(at))
            .map(|&at| {
                let cell = self.plan.cells[at];
                let mut trials = state.rows_of.remove(&at).unwrap_or_default();
                trials.sort_by_key(|t| t.trial);
                let failure = state.failed.get(&at).cloned().or_else(|| {
                    let why = seq_failed.as_ref().filter(|_| at != seq)?;
                    Some(format!(
                        "not measured further: the group's seq reference failed ({why})"
                    ))
                });
                let ctx = CellContext {
                    hardware_threads: self.hardware_threads,
                    shard: self.params.shard.map(|s| s.index),
                    smt: crate::placement::machine_topology().is_smt(cell.cores),
                };
                let reference = seq_failed.is_none().then_some(seq_rows.as_slice());
                summary_row(
                    &cell,
                    work.phase,
                    &trials,
                    reference,
                    failure.as_deref(),
                    &ctx,
                )
            })
            .collect()
    }

    /// Prints the phase's new summary rows, one line per cell.
    fn print_phase(&self, work: &PhaseWork<'_>, rows: &[SummaryRow]) {
        let text = console::phase_lines(self.plan, &work.group, work.phase, work.rounds, rows);
        // A closed standard output ends the sweep like Ctrl-C (checked before the next run).
        self.progress.suspend(|| {
            let _ = crate::output::console::line(&text);
        });
    }
}
