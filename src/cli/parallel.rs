//! The options that say how a run is parallelised, shared (flattened) by `simulate`, `render`,
//! `trace` and `view`. A command words `--strategy`'s help its own way with
//! `#[command(mut_args(parallel::strategy_help("...")))]`.

use clap::{Arg, Args};
use sph_strategies::{Config, StrategyName};

use crate::topology::Pin;

/// Which strategy runs the passes, on how many threads, in how many chunks.
#[derive(Debug, Clone, Args)]
pub struct ParallelArgs {
    /// Parallel strategy (see `bench-sph list`).
    #[arg(long, default_value = "seq", value_parser = super::values::strategy())]
    pub strategy: StrategyName,
    /// Worker threads [default: the machine's hardware threads].
    #[arg(long, value_parser = super::cores)]
    pub cores: Option<usize>,
    /// Chunks per pass, for strategies that use chunks.
    #[arg(long, default_value_t = 10, value_parser = super::chunks)]
    pub chunks: usize,
    /// Where the threads run: none (the operating system decides), compact (fill each physical
    /// core's SMT siblings first) or spread (one thread per physical core first). The calling
    /// thread is pinned too; a CPU the operating system refuses is an error.
    #[arg(long, default_value = "none", value_parser = super::values::pin())]
    pub pin: Pin,
}

/// Gives `--strategy` the help text `help` (for `Command::mut_args`, which edits the option
/// in place: `mut_arg` would move it last and so reorder the usage line and its errors).
pub(super) fn strategy_help(help: &'static str) -> impl FnMut(Arg) -> Arg {
    move |arg| {
        if arg.get_id() == "strategy" {
            arg.help(help)
        } else {
            arg
        }
    }
}

/// [`strategy_help`], and `--strategy` must be given: it has no default.
pub(super) fn strategy_required(help: &'static str) -> impl FnMut(Arg) -> Arg {
    move |arg| {
        if arg.get_id() == "strategy" {
            arg.help(help).required(true).default_value(None)
        } else {
            arg
        }
    }
}

impl ParallelArgs {
    /// The strategy's configuration: `--cores` (default: the machine's hardware threads),
    /// `--chunks` and `--pin` (an error if the operating system refuses one of its CPUs).
    pub fn config(&self) -> anyhow::Result<Config> {
        let config = Config::new(
            self.cores.unwrap_or_else(super::hardware_threads),
            self.chunks,
        );
        Ok(config.placed(crate::placement::placement(self.pin)?))
    }
}
