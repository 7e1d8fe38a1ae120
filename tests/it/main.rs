//! The root package's integration tests, in one test binary: one binary links once instead
//! of once per file. Each file of this
//! directory is a module, named as its test binary was (`cargo test --profile ci --test it
//! cli_sweep::` runs what `--test cli_sweep` ran); `common` holds the helpers they share.
//! The fixtures stay in `tests/fixtures/`, found from `CARGO_MANIFEST_DIR`.
//!
//! The binary needs the test hooks of bench-sph (`sweep --fake-timings`, ...), which exist
//! only with the `testing` cargo feature: Cargo.toml makes it a required feature, so the
//! README's `cargo test --profile ci --workspace --all-features` runs it, and a plain `cargo test
//! --test it` says which feature to add.
//!
//! All modules' tests share one process and its test threads (as many as the machine has
//! cores, as before for one file's tests); tests that run shards one after another take
//! `common::alone()`, one lock for all modules.

mod common;

mod cli_bounded_reads;
mod cli_limits;
mod cli_locks;
mod cli_merge;
mod cli_merge_checks;
mod cli_messages;
mod cli_overhead;
mod cli_ownership;
mod cli_pin;
mod cli_render;
mod cli_report;
mod cli_report_answer;
mod cli_report_compare;
mod cli_report_pin;
mod cli_report_safety;
mod cli_simulate;
mod cli_speedup;
mod cli_sweep;
mod cli_sweep_beside;
mod cli_sweep_safety;
mod cli_trace;
mod cli_validate;
mod docs_links;
mod imports;
mod layers;
mod physics_step;
mod plain_loop;
mod run_hooks;
mod solver_runs;
mod strategies_match_seq;
mod wcsph_physics;
