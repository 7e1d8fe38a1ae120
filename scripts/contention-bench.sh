#!/usr/bin/env bash
# How the strategies hold up when a core is shared (issue 11.5): runs `bench-sph simulate` for
# seq, rayon-chunks, crossbeam-pool and team at 1 and 2 cores, 45 chunks, while ONE busy process
# (`sh -c 'while :; do :; done'`) competes for the cores, and prints per cell the median wall
# time, its spread, the median CPU time and the ratio to the strategy's own 1-core median.
# On a 2-core machine a 2-core run then has three runnable threads for two cores: a strategy
# whose waiting threads neither keep a CPU from a thread of their own that needs it nor give
# their CPU away to the busy process for long stays near its 1-core time (ratio near 1); one
# that does either collapses.
#
# Usage: scripts/contention-bench.sh [--quiet-machine]
#   --quiet-machine   no busy process: the same table for comparison (also: NO_BUSY=1)
# Environment (all optional):
#   REPS=5                      repetitions of every cell, interleaved (rep 1 of every cell,
#                               then rep 2, ...), so a slow spell hits every cell alike
#   STEPS, N                    --steps and --n (default: simulate's own, 1000 and 1000)
#   STRATEGIES="seq rayon-chunks crossbeam-pool team"   CORES="1 2"   CHUNKS=45
#   CARGO_TARGET_DIR            where the release binary is built (default: target)
#
# Run it on an otherwise quiet machine: it warns when the 1-minute load is already >= 0.5.
# Needs bash, cargo, awk, sed, sort; no jq.
set -euo pipefail

usage() {
    sed -n '2,/^set -euo/{/^set -euo/d;s/^# \{0,1\}//;p}' "$0"
}

NO_BUSY="${NO_BUSY:-0}"
for arg in "$@"; do
    case "$arg" in
    --quiet-machine) NO_BUSY=1 ;;
    -h | --help)
        usage
        exit 0
        ;;
    *)
        echo "Error: unknown argument '$arg' (try --help)" >&2
        exit 2
        ;;
    esac
done

REPS="${REPS:-5}"
STRATEGIES="${STRATEGIES:-seq rayon-chunks crossbeam-pool team}"
CORES="${CORES:-1 2}"
CHUNKS="${CHUNKS:-45}"
if ! [[ "$REPS" =~ ^[1-9][0-9]*$ ]]; then
    echo "Error: REPS must be a positive whole number, not '$REPS'" >&2
    exit 2
fi

cd "$(dirname "$0")/.."
TARGET="${CARGO_TARGET_DIR:-target}"
BIN="$TARGET/release/bench-sph"

# Whatever ends the script (an error, Ctrl-C, kill) stops the busy process and removes the
# temporary file; a signal that arrives during a run takes effect when that run returns.
BUSY_PID=""
RUNS="$(mktemp)"
cleanup() {
    if [[ -n "$BUSY_PID" ]]; then
        kill "$BUSY_PID" 2>/dev/null || true
        wait "$BUSY_PID" 2>/dev/null || true
    fi
    rm -f "$RUNS"
}
trap cleanup EXIT
trap 'exit 130' INT
trap 'exit 143' TERM

# Built before the busy process starts, so that it neither slows the build nor waits for it.
cargo build --release --quiet

echo "uptime: $(uptime)"
if [[ -r /proc/loadavg ]]; then
    read -r LOAD _ </proc/loadavg
else
    # "load average(s): 0.52, 0.40, 0.33" (some locales write 0,52).
    LOAD="$(uptime | sed -n 's/.*load averages*: *\([0-9]*[.,][0-9]*\).*/\1/p' | tr , .)"
fi
if awk -v load="${LOAD:-0}" 'BEGIN { exit !(load >= 0.5) }'; then
    echo "warning: the 1-minute load is already $LOAD (>= 0.5): other work is competing," \
        "so these figures are not clean" >&2
fi
echo "hardware threads: $(getconf _NPROCESSORS_ONLN 2>/dev/null || echo '?')," \
    "repetitions: $REPS, chunks: $CHUNKS${STEPS:+, steps: $STEPS}${N:+, n: $N}"

EXTRA=()
if [[ -n "${STEPS:-}" ]]; then EXTRA+=(--steps "$STEPS"); fi
if [[ -n "${N:-}" ]]; then EXTRA+=(--n "$N"); fi

if [[ "$NO_BUSY" == 1 ]]; then
    echo "mode: quiet machine (no busy process)"
else
    sh -c 'while :; do :; done' &
    BUSY_PID=$!
    echo "mode: one busy process competing (pid $BUSY_PID, stopped on exit)"
fi

# One line per run: strategy cores wall_s cpu_s checksum.
json_field() {
    sed -n "s/.*\"$1\":\"\{0,1\}\([^,\"}]*\).*/\1/p"
}
for ((rep = 1; rep <= REPS; rep++)); do
    for strategy in $STRATEGIES; do
        for cores in $CORES; do
            json="$("$BIN" simulate --json --strategy "$strategy" --cores "$cores" \
                --chunks "$CHUNKS" ${EXTRA[@]+"${EXTRA[@]}"})"
            wall="$(json_field wall_s <<<"$json")"
            cpu="$(json_field cpu_s <<<"$json")"
            checksum="$(json_field checksum <<<"$json")"
            if [[ -z "$wall" || -z "$cpu" ]]; then
                echo "Error: no wall_s/cpu_s in the output of $strategy at $cores cores: $json" >&2
                exit 1
            fi
            echo "$strategy $cores $wall $cpu $checksum" >>"$RUNS"
            echo "  rep $rep/$REPS  $strategy  cores $cores  wall ${wall} s  cpu ${cpu} s" >&2
        done
    done
done

# Every run simulates the same thing, so every checksum must be the same.
if [[ "$(awk '{ print $5 }' "$RUNS" | sort -u | wc -l)" -ne 1 ]]; then
    echo "Error: the runs disagree on the final state's checksum:" >&2
    awk '{ print "  " $1 " at " $2 " cores: " $5 }' "$RUNS" | sort -u >&2
    exit 1
fi

# "median min max" of column $3 (wall) or $4 (cpu) of one cell's runs.
cell_stats() {
    awk -v s="$1" -v c="$2" -v col="$3" '$1 == s && $2 == c { print $col }' "$RUNS" |
        sort -g |
        awk '{ v[NR] = $1 }
             END {
                 m = (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2
                 printf "%.4f %.4f %.4f\n", m, v[1], v[NR]
             }'
}

echo
printf '%-16s %5s %13s %19s %12s %14s\n' strategy cores "median wall" "min-max wall" \
    "median CPU" "vs own 1-core"
for strategy in $STRATEGIES; do
    base=""
    for cores in $CORES; do
        read -r wall lo hi < <(cell_stats "$strategy" "$cores" 3)
        read -r cpu _ _ < <(cell_stats "$strategy" "$cores" 4)
        if [[ "$cores" == 1 ]]; then base="$wall"; fi
        ratio="$(awk -v w="$wall" -v b="$base" \
            'BEGIN { if (b > 0) printf "%.2fx", w / b; else print "-" }')"
        printf '%-16s %5s %13s %19s %12s %14s\n' "$strategy" "$cores" "$wall s" \
            "$lo-$hi s" "$cpu s" "$ratio"
    done
done
echo
echo "uptime: $(uptime)"
