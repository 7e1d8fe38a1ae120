#!/usr/bin/env bash
# Reproduces the whole bench-sph study from a fresh clone: build, sweeps, traces, report.
#
# Usage: scripts/reproduce-study.sh [CORES]
#   CORES  worker-thread counts for every sweep, as `bench-sph sweep --cores` takes them
#          (default 1..2; on a 16-core machine: scripts/reproduce-study.sh 1..16).
#
# Writes (replacing earlier results of the same names):
#   results/paper/            the paper's study: seed preset, all-pairs, N = 1000, 1000 steps,
#                             every strategy, chunks 10..200 in steps of 10
#   results/paper-again/      the same sweep again, at once: report/reproducibility/ compares
#                             the two (report --compare: which intervals overlap, which
#                             rankings flip)
#   results/grid/             grid search at N = 1000, 10 000, 100 000, 100 steps
#   results/all-pairs-small/  all-pairs at N = 1000, 3000, 100 steps (chart 6 beside the grid)
#   results/wcsph/            the validated workload beside the toy at the same size: wcsph
#                             and seed, grid, N = 3200 (wcsph: R = 40), 200 steps, every
#                             strategy
#   report/                   charts, REPORT.md and two traces (rayon-chunks, rayon-spawn)
#   report/validation/        the wcsph dam break against Martin & Moyce (1952), R = 40
#   results/pin/, report/pin/ every strategy unpinned and --pin spread (grid, N = 10 000)
#   results/grid-50steps/     the grid sweep again at 50 steps (N = 1000, 10 000), and
#   report/compare/           its comparison with results/grid (report --compare): a
#                             stand-in for a second machine, labelled as one
#   results/scaling/          all-pairs at N = 300 and 1000, 1000 steps, every strategy, with
#                             what a pass costs each and (with a C++ compiler with OpenMP)
#                             the plain loop's OpenMP build, and its own REPORT.md
# Run it on a quiet machine: nothing else should compete for the cores while it measures.
set -euo pipefail

CORES="${1:-1..2}"
cd "$(dirname "$0")/.."

uptime
load=$(cut -d' ' -f1 /proc/loadavg 2>/dev/null || echo 0)
if awk -v l="$load" 'BEGIN {exit !(l >= 0.5)}'; then
    echo "warning: 1-minute load is $load: the machine is not quiet; timings will be contended" >&2
fi

cargo build --release
BIN=target/release/bench-sph

for out in results/paper results/paper-again; do
    "$BIN" sweep --preset seed --neighbors all-pairs --n 1000 --steps 1000 \
        --cores "$CORES" --chunks 10..200:10 --out "$out" --force --no-plots
done
"$BIN" sweep --preset seed --neighbors grid --n 1000,10000,100000 --steps 100 \
    --cores "$CORES" --chunks 10,50,200 --out results/grid --force --no-plots
"$BIN" sweep --preset seed --neighbors all-pairs --n 1000,3000 --steps 100 \
    --strategies rayon-chunks --cores "$CORES" --chunks 50 \
    --out results/all-pairs-small --force --no-plots
"$BIN" sweep --preset seed,wcsph --neighbors grid --n 3200 --steps 200 \
    --cores "$CORES" --chunks 10,50,200 --out results/wcsph --force --no-plots

mkdir -p report
"$BIN" trace --strategy rayon-chunks --cores 2 --chunks 45 --n 1000 \
    --out report/trace-rayon-chunks-2c
"$BIN" trace --strategy rayon-spawn --cores 2 --n 1000 \
    --out report/trace-rayon-spawn-2c

# The report finds the traces under report/ itself. --force: report/ also holds the
# animation (dambreak.gif), which the report leaves untouched.
"$BIN" report results/paper results/grid results/all-pairs-small --out report --force
# The real workload beside the toy, in its own report (re-measured on its own when the wcsph
# step changes, possibly on another machine than the three above).
"$BIN" report results/wcsph --out results/wcsph --force
"$BIN" validate --resolution 40 --out report/validation --force
# Placement (book/src/hyperthreading.md): every strategy unpinned and pinned
# `spread`, reported on its own (its unpinned cells repeat results/grid's N = 10 000 group).
"$BIN" sweep --preset seed --neighbors grid --n 10000 --steps 100 \
    --cores "$CORES" --chunks 10,50 --pin none,spread --out results/pin --force --no-plots
mkdir -p report/pin
"$BIN" report results/pin --out report/pin --force

# A stand-in for a second machine (book/src/commands/report.md, "Comparing machines"): the grid study again at 50
# steps on this machine, compared with --compare, whose banner says it is one machine.
"$BIN" sweep --preset seed --neighbors grid --n 1000,10000 --steps 50 \
    --cores "$CORES" --chunks 10,50,200 --out results/grid-50steps --force --no-plots
mkdir -p report/compare
"$BIN" report results/grid results/grid-50steps --compare --out report/compare --force

# Does the paper study survive a second sweep? The two back-to-back sweeps compared.
mkdir -p report/reproducibility
"$BIN" report results/paper results/paper-again --compare --out report/reproducibility --force

# A study measured while other work used the machine is not one to commit.
# The `contended` column by name: columns are appended over time (reference_shard follows it).
contended=$(awk -F, 'FNR == 1 {for (i = 1; i <= NF; i++) if ($i == "contended") c = i; next}
    $c == "true" {n++} END {print n + 0}' results/paper/summary.csv results/grid/summary.csv \
    results/all-pairs-small/summary.csv results/wcsph/summary.csv results/grid-50steps/summary.csv \
    results/pin/summary.csv results/paper-again/summary.csv)
if [ "$contended" -gt 0 ]; then
    echo "warning: $contended contended cells (see report/REPORT.md): rerun on a quiet machine" >&2
    exit 1
fi
echo "Done: report/REPORT.md (no contended cell)"

# Where the curves bend (book/src/study.md): what a pass costs each strategy, and the plain
# loop's OpenMP build beside them where a C++ compiler with OpenMP is installed.
anchor=()
if scripts/build-plain-loop.sh >/dev/null && [[ -x target/plain-loop/mueller-omp ]]; then
    anchor=(--anchor target/plain-loop/mueller-omp)
else
    echo "no OpenMP build of the plain loop: results/scaling without its anchor" >&2
fi
"$BIN" sweep --preset seed --neighbors all-pairs --n 300,1000 --steps 1000 --cores "$CORES" \
    --chunks 2,4,8,10,20,40 --pass-cost ${anchor[@]+"${anchor[@]}"} --wait-quiet 60 \
    --out results/scaling --force
