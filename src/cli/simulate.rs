//! `bench-sph simulate`: one run of the dam break, timed.

use std::path::PathBuf;

use anyhow::Context;
use clap::Args;
use serde::Serialize;

use crate::checksum::checksum_hex;
use crate::io::dump_csv::{self, DumpInfo};
use crate::io::sink::Sink;
use crate::limits;
use crate::models::Preset;
use crate::output::console;
use crate::run::{RunError, Steps};
use crate::simd::SimdPath;
use crate::solver::{Simulation, StepError};
use crate::sph::neighbors::{NeighborMode, SumOrder};
use crate::topology::Pin;

/// Options of `simulate`.
#[derive(Debug, Clone, Args)]
pub struct SimulateArgs {
    /// The scene: preset, N, neighbour search, seed, initial state.
    #[command(flatten)]
    pub scene: super::scene::SceneArgs,
    /// Number of steps.
    #[arg(long, default_value_t = 1000, value_parser = super::steps)]
    pub steps: usize,
    /// Run until this simulated time instead of a number of steps (s, 0 < T <= 100): stops
    /// after the first step that reaches it (wcsph's time step adapts to the flow).
    #[arg(long, value_name = "SECONDS", value_parser = super::t_end, conflicts_with = "steps")]
    pub t_end: Option<f64>,
    /// Order of the sums over neighbours: index (the sources' order and bits) or cell (the
    /// grid's candidate order: faster, not the sources' bits, still the same bits on every
    /// strategy, core and chunk count; needs --neighbors grid)
    #[arg(long, default_value = "index", value_parser = super::values::order())]
    pub order: SumOrder,
    /// How the passes run: strategy, worker threads, chunks.
    #[command(flatten)]
    pub parallel: super::parallel::ParallelArgs,
    /// Write the final state to CSV (i,x,y,vx,vy,fx,fy,rho,p; exact round-trip), replacing
    /// FILE only when the run ends.
    #[arg(long, value_name = "FILE.csv")]
    pub dump: Option<PathBuf>,
    /// Print one JSON object instead of text.
    #[arg(long)]
    pub json: bool,
    /// Test hooks (only with the `testing` cargo feature).
    #[cfg(feature = "testing")]
    #[command(flatten)]
    pub hooks: super::testing::SimulateHooks,
}

/// What `simulate --json` prints (field names as in the study's CSVs).
#[derive(Debug, Serialize)]
struct Report {
    preset: Preset,
    neighbors: NeighborMode,
    order: SumOrder,
    strategy: String,
    cores: usize,
    chunks: Option<usize>,
    seed: Option<u64>,
    init: Option<String>,
    n: usize,
    #[serde(skip_serializing_if = "Option::is_none")]
    resolution: Option<usize>,
    #[serde(skip_serializing_if = "Option::is_none")]
    walls: Option<usize>,
    steps: usize,
    /// Times `wcsph`'s kept neighbour lists were built (absent for Müller's presets, which
    /// build them every step).
    #[serde(skip_serializing_if = "Option::is_none")]
    list_builds: Option<u64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    simulated_s: Option<f64>,
    wall_s: f64,
    cpu_s: f64,
    particle_steps_per_s: f64,
    checksum: String,
    simd: SimdPath,
    pin: Pin,
}

/// Runs `simulate`.
pub fn run(args: &SimulateArgs) -> anyhow::Result<()> {
    // n: the particles that move; particle-steps count these (wcsph's walls are fixed).
    let (mut sim, n) = args.scene.simulation(args.order)?;
    let walls = sim.state.len() - n;
    // Open the dump before the run, so a bad path costs nothing. It is written to a
    // temporary file and renamed over FILE at the end: a failed or interrupted run leaves
    // FILE as it was.
    let mut dump = args.dump.as_deref().map(Sink::create).transpose()?;
    let config = args.parallel.config()?;
    let steps = match args.t_end {
        None => Steps::timed(args.steps),
        Some(t) => Steps {
            until_s: Some(t),
            ..Steps::timed(limits::MAX_STEPS)
        },
    };
    let strategy = args.parallel.strategy;
    let outcome = args
        .hooks()
        .run_timed_steps(&mut sim, strategy, &config, steps);

    let diverged = matches!(
        outcome,
        Err(RunError::Step(
            StepError::Diverged { .. } | StepError::Unphysical { .. }
        ))
    );
    if let Some(out) = dump.take().filter(|_| outcome.is_ok() || diverged) {
        write_dump(out, &sim, args.scene.preset)?;
    }
    let elapsed = match outcome {
        Ok(e) => e,
        Err(err) if diverged => {
            let note = args
                .dump
                .as_ref()
                .map(|p| format!(" (state at that step written to '{}')", p.display()));
            anyhow::bail!("{err}{}", note.unwrap_or_default());
        }
        Err(err) => return Err(err.into()),
    };

    let info = args.parallel.strategy.info();
    let report = Report {
        preset: args.scene.preset,
        neighbors: args.scene.neighbors,
        order: sim.sum_order(),
        strategy: info.name.to_owned(),
        cores: info.effective_cores(config.cores),
        chunks: info.effective_chunks(args.parallel.chunks),
        // wcsph has no jitter, so no seed.
        seed: (args.scene.init.is_none() && args.scene.preset.is_mueller())
            .then_some(args.scene.seed),
        init: args.scene.init.as_ref().map(|p| p.display().to_string()),
        n,
        resolution: args.scene.wcsph_resolution(),
        walls: (walls > 0).then_some(walls),
        steps: sim.steps_done,
        list_builds: sim.list_builds(),
        simulated_s: args.t_end.map(|_| sim.time_s),
        wall_s: elapsed.wall_s,
        cpu_s: elapsed.cpu_s,
        particle_steps_per_s: (n * sim.steps_done) as f64 / elapsed.wall_s,
        checksum: checksum_hex(&sim.state),
        simd: sim.simd(),
        pin: args.parallel.pin,
    };
    print_report(&report, args.json)
}

/// Writes the state of `sim` (of `preset`) to the dump file and renames it into place.
fn write_dump(mut out: Sink, sim: &Simulation, preset: Preset) -> anyhow::Result<()> {
    let info = DumpInfo {
        preset,
        n: sim.state.len(),
        step: sim.steps_done,
    };
    dump_csv::write(&sim.state, &info, &mut out)
        .with_context(|| format!("cannot write dump file '{}'", out.path().display()))?;
    out.commit()
}

/// Prints a line on standard output; a closed or full stdout is an error, not a panic.
pub(super) fn say(text: &str) -> anyhow::Result<()> {
    console::line(text).context("cannot write to standard output")
}

fn print_report(r: &Report, json: bool) -> anyhow::Result<()> {
    if json {
        return say(&serde_json::to_string(r)?);
    }
    let chunks = r.chunks.map_or_else(|| "n/a".to_owned(), |c| c.to_string());
    say(&format!(
        "preset {}, {} neighbours, strategy {} (cores {}, chunks {chunks}), simd {}, pin {}",
        r.preset, r.neighbors, r.strategy, r.cores, r.simd, r.pin
    ))?;
    let walls = r
        .walls
        .map_or_else(String::new, |w| format!(" (+ {w} fixed wall particles)"));
    let resolution = r
        .resolution
        .map_or_else(String::new, |r| format!(", resolution R = {r}"));
    say(&format!(
        "N = {} particles{walls}{resolution}, {} steps",
        r.n, r.steps
    ))?;
    if r.order == SumOrder::Cell {
        say("sums in cell order: not the sources' bits (same bits on every strategy)")?;
    }
    if let Some(t) = r.simulated_s {
        say(&format!("simulated time {t:.6} s"))?;
    }
    if let Some(b) = r.list_builds {
        say(&format!(
            "neighbour lists built {b} times in {} steps",
            r.steps
        ))?;
    }
    say(&format!(
        "wall {:.3} s, CPU {:.3} s (user+sys), {:.3e} particle-steps/s",
        r.wall_s, r.cpu_s, r.particle_steps_per_s
    ))?;
    say(&format!("checksum {}", r.checksum))?;
    Ok(())
}

impl SimulateArgs {
    /// The test hooks given; none in a build without the `testing` feature.
    fn hooks(&self) -> super::testing::SimulateHooks {
        #[cfg(feature = "testing")]
        return self.hooks.clone();
        #[cfg(not(feature = "testing"))]
        super::testing::SimulateHooks::default()
    }
}
