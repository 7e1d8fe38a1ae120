#!/usr/bin/env bash
# Proves a refactor left every output byte-identical: runs the same deterministic commands
# with the binary built at BASE (a git revision, default HEAD~1) and with the working tree's,
# then diffs the two output trees.
#
# Usage: scripts/outputs-unchanged.sh [BASE]
#   BASE_BIN=path  use this binary for BASE instead of building it (in target/outputs-base/).
#
# The commands: the committed reports regenerated from the committed results (traces included;
# the comparisons, the placement study, and a comparison of two machines),
# two sweeps under the test hooks --fake-timings/--fake-contention (one contended, one
# oversubscribed cell) and their report, a third interrupted and resumed, simulate
# --json/--dump on three strategies and from an --init file, render to a GIF and to PNG
# frames, list, a trace (its configuration and counts), two errors. Left out of the diff: what
# a run measures (simulate's and the trace's wall and CPU times; the sweeps' are fake), dates,
# the commit in build lines, the sweep's time estimate and its lock files' PIDs. Exit status 0 when the trees are identical.
set -euo pipefail
cd "$(dirname "$0")/.."
BASE="${1:-HEAD~1}"
work=$(mktemp -d)
trap 'git worktree remove --force "$work/base-src" >/dev/null 2>&1 || true; rm -rf "$work"' EXIT

# Both binaries are built with the test hooks (the `testing` feature; revisions before it had
# them without a feature), each in its own target directory: target/release stays the shipped
# build.
CARGO_TARGET_DIR="$PWD/target/outputs-new" cargo build --release --quiet --features testing
NEW="$PWD/target/outputs-new/release/bench-sph"
if [ -z "${BASE_BIN:-}" ]; then
    git worktree add --quiet --detach "$work/base-src" "$BASE"
    base_features=()
    if grep -q '^testing = ' "$work/base-src/Cargo.toml"; then base_features=(--features testing); fi
    CARGO_TARGET_DIR="$PWD/target/outputs-base" cargo build --release --quiet \
        --manifest-path "$work/base-src/Cargo.toml" "${base_features[@]}"
    BASE_BIN="$PWD/target/outputs-base/release/bench-sph"
fi

# Runs every command with binary $1 in directory $2 (relative paths only, so the trees compare).
outputs() {
    local bin="$work/bin/bench-sph" out=$2 repo=$PWD
    set +e # commands that fail on purpose record their exit status instead
    # The same path for both binaries: meta.json and REPORT.md show the command line.
    mkdir -p "$work/bin" && cp "$1" "$bin"
    mkdir -p "$out" && cd "$out"
    ln -s "$repo/results" results
    mkdir report && cp -r "$repo"/report/trace-* report/
    { "$bin" report results/paper results/grid results/all-pairs-small results/wcsph --out report; echo "rc=$?"; } > report.stdout 2>&1
    # The committed comparisons (two runs set apart with --compare), a placement study, and
    # two machines (sides by meta.json's machine).
    { "$bin" report --compare results/grid results/grid-50steps --out compare; echo "rc=$?"; } > compare.stdout 2>&1
    { "$bin" report --compare results/paper results/paper-again --out reproducibility; echo "rc=$?"; } > reproducibility.stdout 2>&1
    { "$bin" report results/pin --out pin; echo "rc=$?"; } > pin.stdout 2>&1
    { "$bin" report results/paper results/xeon-16-all-pairs --out machines; echo "rc=$?"; } > machines.stdout 2>&1
    { "$bin" sweep --preset seed --neighbors grid,all-pairs --n 200,300 --steps 5 --cores 1..3 \
        --chunks 2,7 --trials 3 --warmup 0 --seed 7 --fake-timings 1.0:1.1,0.5:0.9,0.6,0.7:1.3,0.4 \
        --fake-contention 0,0,0,0.6,0 --out sw1; echo "rc=$?"; } > sw1.stdout 2>&1
    { "$bin" sweep --preset cpp --n 100 --steps 3 --cores 1,2 --chunks 3 --trials 2 --warmup 0 \
        --strategies rayon-chunks,std-static --fake-timings 0.3,0.2 --out sw2; echo "rc=$?"; } > sw2.stdout 2>&1
    { "$bin" report sw1 sw2 --out rep12; echo "rc=$?"; } > rep12.stdout 2>&1
    # A sweep stopped as if by Ctrl-C after 2 cells, then resumed (with its charts).
    { "$bin" sweep --n 100 --steps 2 --cores 1,2 --chunks 2 --trials 2 --warmup 0 \
        --strategies rayon-chunks,std-static --fake-timings 0.3,0.2 --stop-after-runs 2 \
        --no-plots --out sw3; echo "rc=$?"; } > sw3.stdout 2>&1
    { "$bin" sweep --resume sw3; echo "rc=$?"; } > sw3-resume.stdout 2>&1
    local timed='s/"(wall_s|cpu_s|particle_steps_per_s)":[^,}]*/"\1":X/g'
    for s in seq rayon-chunks crossbeam-pool; do
        "$bin" simulate --n 300 --steps 20 --strategy "$s" --cores 2 --json --dump "dump-$s.csv" \
            | sed -E "$timed" > "sim-$s.json"
    done
    "$bin" simulate --init dump-seq.csv --steps 5 --json | sed -E "$timed" > sim-init.json
    "$bin" render --n 300 --steps 40 --every 10 --out anim.gif > render.stdout 2>&1
    "$bin" render --n 300 --steps 20 --every 10 --frames frames > frames.stdout 2>&1
    "$bin" render --preset wcsph --resolution 8 --steps 40 --every 10 --out wcsph.gif > wcsph.stdout 2>&1
    "$bin" render --preset cpp --n 300 --steps 20 --every 10 --color density --out density.gif \
        > density.stdout 2>&1
    "$bin" list > list.txt
    # A trace: its meta.json but the measured times, and stats.csv's counts per pass and in all
    # (not its times, nor which and how many threads ran the calls: that is the scheduler's).
    "$bin" trace --n 300 --steps 3 --strategy rayon-chunks --cores 2 --chunks 4 --out tr > trace.stdout 2>&1
    sed -i -E 's/"(wall_s|cpu_s|worker_threads|workers_used)": [^,]*/"\1": X/' tr/meta.json
    grep -v '^worker,' tr/stats.csv | cut -d, -f1,2,4 > tr/stats-counts.csv
    rm -f tr/stats.csv tr/timeline.png tr/trace.json trace.stdout
    { "$bin" simulate --n 0; echo "rc=$?"; } > err1.txt 2>&1
    { "$bin" simulate --n 100 --steps 200000000000; echo "rc=$?"; } > err2.txt 2>&1
    rm -f results
    # Lock files hold a PID (older versions: sweep.lock; now bench-sph.lock).
    find . \( -name sweep.lock -o -name bench-sph.lock \) -delete
    # What a run measures, when it ran and which build ran it.
    find . -name meta.json -exec sed -i -E \
        's/"(started|finished)[a-z_]*": "[^"]*"/"\1": "X"/g; s/"(git_commit|git_dirty)": [^,]*/"\1": X/g' {} +
    sed -i -E 's/\(build [0-9a-f]+(-dirty)?\)/(build X)/; s/commit [0-9a-f]{40}(, with uncommitted changes)?/commit X/g; s/[0-9]{4}-[0-9]{2}-[0-9]{2}T[0-9:]+Z/TIME/g' */REPORT.md
    sed -i -E 's/[0-9.]+ s in all, [0-9.]+ s of it simulating/T/; s/seq ≈ [0-9.]+ ms/seq ≈ X ms/; s/estimated time: (at most )?about [0-9.]+ [a-z]+/estimated time: X/' ./*.stdout
    cd "$repo"
    set -e
}

outputs "$BASE_BIN" "$work/base"
outputs "$NEW" "$work/new"
if diff -r "$work/base" "$work/new"; then
    echo "outputs unchanged ($BASE → working tree)"
else
    echo "outputs differ ($BASE → working tree): see the diff above" >&2
    exit 1
fi
