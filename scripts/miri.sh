#!/usr/bin/env bash
# Runs the tests of the workspace's only `unsafe` code (strategies/src/erased_job: the two
# boards that hand a job borrowed for one pass to long-lived threads) and of `team`'s share
# bookkeeping under Miri, which reports undefined behaviour: a use after the borrow ended, a
# data race, an unsynchronised read. Each test runs under every scheduling seed in SEEDS, so
# Miri tries that many interleavings of the threads.
#
# Usage: scripts/miri.sh [SEEDS]      (default SEEDS: 0..16; FROM..TO, 0 <= FROM < TO <= 1000)
# Needs the nightly toolchain with Miri:
#     rustup toolchain install nightly --component miri,rust-src
# Takes a few minutes (Miri interprets; each seed's tests take about 20 s).
#
# Leaks are ignored: `KernelPanic::from_payload` forgets every panic payload on purpose
# (strategies/src/panic.rs says why), and the panic tests make some.
set -euo pipefail

SEEDS="${1:-0..16}"
# A range FROM..TO of seeds, 0 <= FROM < TO <= 1000 (each seed runs every test once).
if ! [[ "$SEEDS" =~ ^([0-9]{1,4})\.\.([0-9]{1,4})$ ]] || ((10#${BASH_REMATCH[1]} >= 10#${BASH_REMATCH[2]})) ||
    ((10#${BASH_REMATCH[2]} > 1000)); then
    echo "Error: SEEDS must be FROM..TO with 0 <= FROM < TO <= 1000, not '$SEEDS'" >&2
    exit 2
fi
cd "$(dirname "$0")/.."

if ! cargo +nightly miri --version >/dev/null 2>&1; then
    echo "Error: no Miri: rustup toolchain install nightly --component miri,rust-src" >&2
    exit 1
fi
MIRIFLAGS="-Zmiri-ignore-leaks -Zmiri-many-seeds=$SEEDS" CARGO_TARGET_DIR=target/miri \
    cargo +nightly miri test -p sph-strategies --lib -- erased_job team::
