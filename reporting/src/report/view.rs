//! One group of a study as the report reads it, built once per group ([`GroupView::of`]) and
//! read by every table, chart and finding: its grid rows (every cell measured), its
//! confirmation rows (the cells the grid chose, measured again), each cell's runs by round,
//! and how its sweep was measured ([`Design`]).
//!
//! - A strategy's **best cell** at a core count ([`GroupView::best_per_cores`]) is the grid's
//!   choice: the lowest grid mean, a contended cell only where nothing else was measured.
//!   Where the group has confirmation rows, its numbers are theirs — runs that did not choose
//!   it. Without them (a merge of shards, `--confirm-rounds 0`) the same runs chose and
//!   measured it, so it is biased fast (the winner's curse), and [`Best::confirmed`] says so.
//! - **Comparisons** pair runs by round ([`Runs::ratio`]): two cells' runs pair only where
//!   they ran in the same rounds — the same sweep, phase and shard ([`Batch`]) — of a sweep
//!   measured in shuffled rounds.

use std::collections::{BTreeSet, HashMap};

use super::cell::{Batch, Best, Runs};
use super::select::{self, SeriesKey};
use sph_harness::results::key::{Cell, Group};
use sph_harness::results::load::Sweep;
use sph_harness::results::meta::Meta;
use sph_harness::results::params::Schedule;
use sph_harness::results::rows::{Contended, Phase, SummaryRow, TrialRow, fastest};
use sph_harness::results::summarize::by_round;
use sph_strategies::StrategyName;

/// How a sweep ordered its runs and computed its intervals: whether its rounds pair.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Design {
    /// Shuffled rounds, Student-t intervals: a round's runs of two cells pair.
    Rounds,
    /// `--schedule cells`: each cell's runs back to back, so a round's runs of two cells ran
    /// minutes apart and pairing them does not cancel the machine's drift.
    Cells,
    /// Written before rounds: cell after cell, percentile-bootstrap intervals that under-cover,
    /// speedups that divide two means.
    BeforeRounds,
}

impl Design {
    /// How the sweep of `meta` was measured.
    pub fn of(meta: &Meta) -> Design {
        if meta.statistics.as_ref().is_none_or(|s| s.before_rounds()) {
            Design::BeforeRounds
        } else if meta.params.schedule == Schedule::Cells {
            Design::Cells
        } else {
            Design::Rounds
        }
    }

    /// Whether comparisons pair runs by round (and so findings may be drawn).
    pub fn pairs(self) -> bool {
        self == Design::Rounds
    }
}

/// One group of a study: see the module docs.
#[derive(Debug, Clone)]
pub struct GroupView {
    /// The group.
    pub group: Group,
    /// How its sweep was measured.
    pub design: Design,
    /// Its grid rows (every cell measured, failed ones too), in plan order.
    pub rows: Vec<SummaryRow>,
    /// Its confirmation rows (empty without a confirmation phase).
    pub confirmed: Vec<SummaryRow>,
    /// The rounds planned: (grid, confirmation).
    pub rounds: (usize, usize),
    /// Whether its sweep is one shard or a merge of shards (neither has confirmation rounds).
    pub sharded: bool,
    /// Whether some of its rows come from a directory without `trials.csv`, whose statistics
    /// could not be checked against the runs ([`Sweep::without_trials`]).
    pub unchecked: bool,
    /// Each cell's runs per phase.
    runs: HashMap<(Cell, Phase), Runs>,
}

impl GroupView {
    /// The groups of `sweeps` (one machine's study), in the order they first appear.
    pub fn of<'a>(sweeps: impl IntoIterator<Item = &'a Sweep>) -> Vec<GroupView> {
        let mut out: Vec<GroupView> = Vec::new();
        for (source, s) in sweeps.into_iter().enumerate() {
            let design = Design::of(&s.meta);
            let mut trials: HashMap<(Cell, Phase), Vec<&TrialRow>> = HashMap::new();
            for t in &s.trials {
                trials.entry(t.phased_key()).or_default().push(t);
            }
            for r in s.rows.iter().chain(&s.confirmed) {
                let at = match out.iter().position(|v| v.group == r.group()) {
                    Some(at) => at,
                    None => {
                        out.push(GroupView::new(r.group(), design, &s.meta));
                        out.len() - 1
                    }
                };
                let of_cell: Vec<TrialRow> = trials
                    .get(&r.phased_key())
                    .map_or_else(Vec::new, |t| t.iter().map(|&t| t.clone()).collect());
                let batch = Batch {
                    source,
                    phase: r.phase,
                    shard: r.reference_shard,
                    paired: design.pairs(),
                };
                out[at].unchecked |= s.without_trials;
                out[at].add(r.clone(), batch, &of_cell);
            }
        }
        out
    }

    fn new(group: Group, design: Design, meta: &Meta) -> GroupView {
        GroupView {
            group,
            design,
            rows: Vec::new(),
            confirmed: Vec::new(),
            rounds: (meta.params.trials, meta.params.confirm_rounds),
            sharded: meta.merge.is_some() || meta.params.shard.is_some(),
            unchecked: false,
            runs: HashMap::new(),
        }
    }

    /// Adds `row` with its trial rows `trials`, runs of `batch`.
    fn add(&mut self, row: SummaryRow, batch: Batch, trials: &[TrialRow]) {
        let runs = Runs {
            batch,
            rounds: by_round(trials),
        };
        self.runs.insert(row.phased_key(), runs);
        match row.phase {
            Phase::Grid => self.rows.push(row),
            Phase::Confirm => self.confirmed.push(row),
        }
    }

    /// The runs of `row`'s cell in its phase (none where its trials were not read).
    pub fn runs(&self, row: &SummaryRow) -> Runs {
        self.runs.get(&row.phased_key()).cloned().unwrap_or(Runs {
            batch: Batch {
                source: usize::MAX,
                phase: row.phase,
                shard: row.reference_shard,
                paired: false,
            },
            rounds: Vec::new(),
        })
    }

    /// Whether the group's best cells come from confirmation rounds.
    pub fn is_confirmed(&self) -> bool {
        !self.confirmed.is_empty()
    }

    /// The rows the findings rest on: the confirmation's where the group has them, else the
    /// grid's.
    pub fn findings_rows(&self) -> &[SummaryRow] {
        if self.is_confirmed() {
            &self.confirmed
        } else {
            &self.rows
        }
    }

    /// The usable `seq` reference of the rows the findings rest on.
    pub fn reference(&self) -> Option<&SummaryRow> {
        self.findings_rows()
            .iter()
            .find(|r| r.is_reference() && r.is_usable())
    }

    /// `row`'s numbers with its runs (and, for a confirmation row, its cell's grid runs).
    pub fn best(&self, row: &SummaryRow) -> Option<Best> {
        let mut best = Best::of(row, self.runs(row))?;
        if row.phase == Phase::Confirm {
            best.grid_runs = self.runs.get(&(row.key(), Phase::Grid)).cloned();
        }
        Some(best)
    }

    /// The best cell of the series `key` at each core count it was measured at, by cores
    /// (see the module docs).
    pub fn best_per_cores(&self, key: SeriesKey) -> Vec<Best> {
        let line = |rows: &[SummaryRow], cores: usize| -> Vec<SummaryRow> {
            rows.iter()
                .filter(|r| r.is_usable() && key.holds(r) && r.cores == cores)
                .cloned()
                .collect()
        };
        let cores: BTreeSet<usize> = self
            .rows
            .iter()
            .filter(|r| r.is_usable() && key.holds(r))
            .map(|r| r.cores)
            .collect();
        cores
            .into_iter()
            .filter_map(|c| {
                let confirmed = line(&self.confirmed, c);
                // The grid's choice among the cells it sent to confirmation.
                let grid: Vec<SummaryRow> = line(&self.rows, c)
                    .into_iter()
                    .filter(|g| {
                        confirmed.is_empty() || confirmed.iter().any(|r| r.key() == g.key())
                    })
                    .collect();
                let chosen = fastest(&grid, Contended::LastResort)?;
                let row = confirmed
                    .iter()
                    .find(|r| r.key() == chosen.key())
                    .unwrap_or(chosen);
                self.best(row)
            })
            .collect()
    }

    /// The core counts of the group's usable cells (any strategy but `seq`), ascending.
    pub fn cores(&self) -> Vec<usize> {
        select::cores(&self.rows, &self.group)
    }

    /// Every strategy of the group but `seq`, in the order they first appear.
    pub fn parallel_strategies(&self) -> Vec<StrategyName> {
        select::strategies(&self.rows, &self.group)
            .into_iter()
            .filter(|&s| s != StrategyName::Seq)
            .collect()
    }

    /// Each series of the group (every strategy but `seq`, at each of its placements) with
    /// its best cell per core count.
    pub fn series_bests(&self) -> Vec<(SeriesKey, Vec<Best>)> {
        select::series(&self.rows, &self.group)
            .into_iter()
            .map(|k| (k, self.best_per_cores(k)))
            .collect()
    }

    /// The other cell of `best`'s line that the confirmation measured (the grid's runner-up,
    /// for a strategy with chunks), if any.
    pub fn runner_up(&self, best: &Best) -> Option<Best> {
        if !best.confirmed {
            return None;
        }
        let r = self.confirmed.iter().find(|r| {
            r.is_usable()
                && r.strategy == best.strategy
                && r.pin == best.pin
                && r.cores == best.cores
                && r.chunks != best.chunks
        })?;
        self.best(r)
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use sph_harness::results::fixtures::sweep_on;
    use sph_harness::results::fixtures::trials;
    use sph_harness::results::summarize::{CellContext, summary_row};
    use sph_harness::topology::Pin;
    use sph_strategies::StrategyName;

    /// One cell to measure: strategy, cores, chunks, placement and its walls per round.
    pub(crate) type Spec<'a> = (StrategyName, usize, Option<usize>, Pin, &'a [f64]);

    /// The summary and trial rows of `specs` (the first `seq`) in `phase`, in the tests' small
    /// group ([`measured_in`]).
    pub(crate) fn measured(specs: &[Spec<'_>], phase: Phase) -> (Vec<SummaryRow>, Vec<TrialRow>) {
        use sph_solver::sph::neighbors::NeighborMode;
        measured_in(
            sph_harness::results::key::test_group(NeighborMode::AllPairs),
            specs,
            phase,
        )
    }

    /// The summary and trial rows of `specs` (the first `seq`) of `group` in `phase`, as the
    /// sweep writes them: each summary a function of its trials, speedups paired by round.
    pub(crate) fn measured_in(
        group: Group,
        specs: &[Spec<'_>],
        phase: Phase,
    ) -> (Vec<SummaryRow>, Vec<TrialRow>) {
        let ctx = CellContext {
            hardware_threads: 2,
            shard: None,
            smt: Some(false),
        };
        let cell = |&(strategy, cores, chunks, pin, _): &Spec<'_>| Cell {
            group,
            strategy,
            cores,
            chunks,
            pin,
        };
        let runs = |s: &Spec<'_>| {
            let mut t = trials(&cell(s), s.4);
            for t in &mut t {
                t.phase = phase;
            }
            t
        };
        let seq = runs(&specs[0]);
        let mut rows = Vec::new();
        let mut all = Vec::new();
        for s in specs {
            let t = runs(s);
            rows.push(summary_row(&cell(s), phase, &t, Some(&seq), None, &ctx));
            all.extend(t);
        }
        (rows, all)
    }

    /// The one group of `specs` measured in paired grid rounds.
    pub(crate) fn view(specs: &[Spec<'_>]) -> GroupView {
        let (rows, trials) = measured(specs, Phase::Grid);
        with_trials(rows, trials)
    }

    /// The groups of `rows` and `trials`, one sweep in shuffled rounds.
    pub(crate) fn views(rows: Vec<SummaryRow>, trials: Vec<TrialRow>) -> Vec<GroupView> {
        let mut sweep = sweep_on("d", "Xeon", 2, Vec::new());
        let (confirmed, grid) = rows.into_iter().partition(|r| r.phase == Phase::Confirm);
        (sweep.rows, sweep.confirmed, sweep.trials) = (grid, confirmed, trials);
        GroupView::of([&sweep])
    }

    /// The one group of `rows` and `trials`, a sweep in shuffled rounds.
    pub(crate) fn with_trials(rows: Vec<SummaryRow>, trials: Vec<TrialRow>) -> GroupView {
        views(rows, trials).remove(0)
    }

    /// The one group of `rows`, without trials (nothing pairs).
    pub(crate) fn of_rows(rows: Vec<SummaryRow>) -> GroupView {
        with_trials(rows, Vec::new())
    }

    const SEQ: [f64; 3] = [4.0, 4.4, 3.6];

    #[test]
    fn a_confirmed_group_takes_the_grids_choice_with_the_confirmations_numbers() {
        use StrategyName::{RayonChunks, Seq};
        let none = Pin::None;
        let (mut rows, mut trials) = measured(
            &[
                (Seq, 1, None, none, &SEQ),
                (RayonChunks, 2, Some(5), none, &[2.1, 2.3, 1.9]),
                (RayonChunks, 2, Some(10), none, &[2.0, 2.2, 1.8]),
                (RayonChunks, 2, Some(20), none, &[2.4, 2.6, 2.2]),
            ],
            Phase::Grid,
        );
        // Measured again, 10 chunks turns out slower than 5: the grid's choice stands.
        let (c_rows, c_trials) = measured(
            &[
                (Seq, 1, None, none, &SEQ),
                (RayonChunks, 2, Some(5), none, &[1.0, 1.1, 0.9]),
                (RayonChunks, 2, Some(10), none, &[2.0, 2.2, 1.8]),
            ],
            Phase::Confirm,
        );
        rows.extend(c_rows);
        trials.extend(c_trials);
        let v = with_trials(rows, trials);
        assert!(v.is_confirmed());
        let best = v.best_per_cores(SeriesKey::unpinned(RayonChunks));
        assert_eq!(best.len(), 1);
        let b = &best[0];
        assert_eq!((b.chunks, b.confirmed, b.mean_s), (Some(10), true, 2.0));
        assert_eq!(b.runs.batch.phase, Phase::Confirm);
        let up = v.runner_up(b).unwrap();
        assert_eq!(up.chunks, Some(5));
        // Paired by round: 5 chunks took half the time of 10 in every round.
        let r = up.runs.ratio(&b.runs).unwrap();
        assert!((r.value - 0.5).abs() < 1e-12 && r.resolved(), "{r:?}");
        assert_eq!(v.reference().unwrap().phase, Phase::Confirm);
    }

    #[test]
    fn a_strategy_the_confirmation_left_out_is_ordered_by_the_grids_rounds() {
        use StrategyName::{RayonChunks, RayonSpawn, Seq};
        let none = Pin::None;
        let (mut rows, mut trials) = measured(
            &[
                (Seq, 1, None, none, &SEQ),
                (RayonChunks, 2, Some(10), none, &[2.0, 2.2, 1.8]),
                (RayonSpawn, 2, None, none, &[5.0, 5.5, 4.5]),
            ],
            Phase::Grid,
        );
        // rayon-spawn took more than twice the fastest cell's time: not confirmed.
        let (c_rows, c_trials) = measured(
            &[
                (Seq, 1, None, none, &SEQ),
                (RayonChunks, 2, Some(10), none, &[2.0, 2.1, 1.9]),
            ],
            Phase::Confirm,
        );
        rows.extend(c_rows);
        trials.extend(c_trials);
        let v = with_trials(rows, trials);
        let chunks = &v.best_per_cores(SeriesKey::unpinned(RayonChunks))[0];
        let spawn = &v.best_per_cores(SeriesKey::unpinned(RayonSpawn))[0];
        assert!(chunks.confirmed && !spawn.confirmed);
        assert_eq!(
            spawn.runs.ratio(&chunks.runs),
            None,
            "other phases never pair"
        );
        // In the grid's rounds rayon-spawn took 2.5 times as long, round by round.
        match crate::report::verdict::order(chunks, spawn) {
            crate::report::verdict::Order::AFaster(r) => {
                assert!((r.value - 2.5).abs() < 1e-9, "{r:?}");
            }
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn without_confirmation_the_grid_chooses_and_measures_and_says_so() {
        use StrategyName::{RayonChunks, Seq};
        let v = view(&[
            (Seq, 1, None, Pin::None, &SEQ),
            (RayonChunks, 2, Some(5), Pin::None, &[2.1, 2.3, 1.9]),
            (RayonChunks, 2, Some(10), Pin::None, &[2.0, 2.2, 1.8]),
        ]);
        let b = &v.best_per_cores(SeriesKey::unpinned(RayonChunks))[0];
        assert_eq!((b.chunks, b.confirmed), (Some(10), false));
        assert_eq!(v.runner_up(b), None);
        assert_eq!(v.design, Design::Rounds);
    }

    #[test]
    fn runs_pair_only_within_one_batch_of_a_sweep_in_rounds() {
        let batch = Batch {
            source: 0,
            phase: Phase::Grid,
            shard: Some(1),
            paired: true,
        };
        let a = Runs {
            batch,
            rounds: vec![(1, 1.0), (2, 1.1), (3, 0.9)],
        };
        let b = Runs {
            batch,
            rounds: vec![(1, 2.0), (2, 2.2), (3, 1.8)],
        };
        assert!(a.ratio(&b).unwrap().resolved());
        for other in [
            Batch {
                shard: Some(2),
                ..batch
            },
            Batch {
                phase: Phase::Confirm,
                ..batch
            },
            Batch { source: 1, ..batch },
        ] {
            let b = Runs {
                batch: other,
                ..b.clone()
            };
            assert_eq!(a.ratio(&b), None, "{other:?}");
        }
        let unpaired = |r: &Runs| Runs {
            batch: Batch {
                paired: false,
                ..r.batch
            },
            ..r.clone()
        };
        assert_eq!(unpaired(&a).ratio(&unpaired(&b)), None);
    }
}
