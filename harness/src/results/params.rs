//! Every parameter of a sweep: what `meta.json` records and what `--resume` reads back
//! (checked by [`crate::sweep::params`]).

use std::path::PathBuf;

use serde::{Deserialize, Serialize};
use sph_strategies::StrategyName;

use super::names::name_list;
use super::shard::Shard;
use crate::topology::Pin;
use sph_solver::models::Preset;
use sph_solver::simd::SimdPath;
use sph_solver::sph::neighbors::NeighborMode;

/// The parameters of a sweep, after parsing and expansion: the lists are sorted and free of
/// repeats, so two sweeps with equal parameters have the same plan.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SweepParams {
    /// Strategies to measure, in registry order (`seq` is measured in any case).
    #[serde(with = "name_list")]
    pub strategies: Vec<StrategyName>,
    /// Presets (one group each, multiplied by the other group keys).
    #[serde(with = "name_list")]
    pub presets: Vec<Preset>,
    /// Neighbour searches.
    #[serde(with = "name_list")]
    pub neighbors: Vec<NeighborMode>,
    /// Particle counts.
    pub n: Vec<usize>,
    /// Steps per run.
    pub steps: usize,
    /// Worker-thread counts.
    pub cores: Vec<usize>,
    /// Chunk counts, for strategies that use chunks.
    pub chunks: Vec<usize>,
    /// Timed runs per cell: the rounds of the grid phase (`--trials`).
    pub trials: usize,
    /// Untimed runs: of the group's `seq` before its first round (`rounds`; one such run, the
    /// reference run, happens even with 0), or before each cell's trials (`cells`).
    pub warmup: usize,
    /// The order of the runs (`--schedule`); `cells` in directories written before rounds.
    #[serde(default = "Schedule::before_rounds")]
    pub schedule: Schedule,
    /// Rounds of the confirmation phase (`--confirm-rounds`): each strategy's best cell (and
    /// runner-up) per core count measured again; 0 for none (and in directories written
    /// before the phase existed).
    #[serde(default)]
    pub confirm_rounds: usize,

    /// Seed of the initial jitter.
    pub seed: u64,
    /// SIMD path of the neighbour tests (`--simd`, else the widest the CPU ran); absent in
    /// directories written before it was recorded. `--resume` runs the recorded path.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub simd: Option<SimdPath>,
    /// Thread placements (`--pin`), each a cell dimension of every strategy but the `seq`
    /// reference (which runs unpinned); `["none"]` in directories written before `--pin`.
    /// Not written when it is `["none"]`, so that an unpinned sweep's `meta.json`, and the plan
    /// fingerprint of shards written before `--pin`, stay as they were.
    #[serde(default = "unpinned", skip_serializing_if = "is_unpinned")]
    pub pin: Vec<Pin>,
    /// Which part of the plan this sweep runs (`--shard I/K`); absent for the whole plan.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shard: Option<Shard>,
    /// Whether the sweep measures what a pass costs each strategy at each core count
    /// (`--pass-cost`), after its cells, into `pass-cost.csv`.
    #[serde(default, skip_serializing_if = "is_false")]
    pub pass_cost: bool,
    /// The plain loop's OpenMP build the sweep runs at each core count after its cells
    /// (`--anchor PATH`), into `anchor.csv`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub anchor: Option<PathBuf>,
    /// Test only: trial times replacing the measured ones (see [`crate::sweep::timing`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fake_timings: Option<String>,
    /// Test only: foreign-CPU shares replacing the measured ones (see [`crate::sweep::timing`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fake_contention: Option<String>,
}

/// The order of a sweep's runs (see [`crate::sweep::schedule`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Schedule {
    /// Rounds in a shuffled order: in each round every cell of a group runs once.
    Rounds,
    /// Each cell's runs back to back, cell after cell in plan order (the first versions').
    Cells,
}

impl Schedule {
    /// What directories written before `schedule` was recorded ran.
    fn before_rounds() -> Schedule {
        Schedule::Cells
    }

    /// The name on the command line and in `meta.json`.
    pub fn as_str(self) -> &'static str {
        match self {
            Schedule::Rounds => "rounds",
            Schedule::Cells => "cells",
        }
    }
}

/// Whether a flag is off (then `meta.json` leaves it out, and the plan fingerprints of
/// sweeps written before it stay as they were).
fn is_false(flag: &bool) -> bool {
    !flag
}

/// `--pin`'s default, and what sweeps written before it ran: the operating system's placement.
fn unpinned() -> Vec<Pin> {
    vec![Pin::None]
}

/// Whether `pin` is [`unpinned`]'s.
fn is_unpinned(pin: &[Pin]) -> bool {
    pin == [Pin::None]
}

impl SweepParams {
    /// The plan's fingerprint: FNV-1a (64-bit, [`sph_solver::checksum::fingerprint`]) of these
    /// parameters as `meta.json` writes them, without the shard, as 16 hex digits. The shards
    /// of one plan share it; any other parameter that differs changes it.
    pub fn fingerprint(&self) -> String {
        let whole = SweepParams {
            shard: None,
            ..self.clone()
        };
        let json = serde_json::to_vec(&whole).expect("the parameters serialize");
        format!("{:016x}", sph_solver::checksum::fingerprint(&json))
    }
}

#[cfg(any(test, feature = "testing"))]
impl SweepParams {
    /// A small sweep for unit tests, which change what they test: rayon-chunks, the `seed`
    /// preset, all-pairs, N = 60, 3 steps, cores 1 and 2, chunks 2 and 5, 2 rounds, no warm-up
    /// beyond the reference run, no confirmation, seed 1, unpinned, the whole plan.
    pub fn small() -> SweepParams {
        SweepParams {
            strategies: vec![StrategyName::RayonChunks],
            presets: vec![Preset::Seed],
            neighbors: vec![NeighborMode::AllPairs],
            n: vec![60],
            steps: 3,
            cores: vec![1, 2],
            chunks: vec![2, 5],
            trials: 2,
            warmup: 0,
            schedule: Schedule::Rounds,
            confirm_rounds: 0,
            seed: 1,
            simd: None,
            fake_timings: None,
            fake_contention: None,
            pin: unpinned(),
            shard: None,
            pass_cost: false,
            anchor: None,
        }
    }
}
