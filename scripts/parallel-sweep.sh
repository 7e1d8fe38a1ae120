#!/usr/bin/env bash
# Runs a bench-sph sweep as K shards, on several machines over ssh with GNU parallel, or one
# after another on this machine, then merges them and draws the report (book/src/commands/merge.md).
#
# Usage: scripts/parallel-sweep.sh -k K -o RESULTS_DIR [-S HOST,HOST...] [-f | -r] [-n]
#                                  -- SWEEP PLAN OPTIONS
#   -k K            shards, 1..1024; shard I runs
#                   bench-sph sweep PLAN --shard I/K --out RESULTS_DIR/shard-I
#   -o RESULTS_DIR  gets shard-1 .. shard-K, merged/ (the merged results and REPORT.md) and
#                   sharding.txt (K and the plan, for -r)
#   -S HOSTS        ssh logins (host or user@host), comma-separated: one shard at a time runs
#                   on each (GNU parallel -j1); a multiple of their number for K keeps them
#                   all busy to the end. Without -S: this machine, one shard after another.
#   -f              RESULTS_DIR may hold an earlier sharded sweep: it is replaced
#   -r              continue the sharded sweep in RESULTS_DIR: complete shards are kept,
#                   unfinished ones continue with `sweep --resume`; K and the plan come from
#                   RESULTS_DIR/sharding.txt (-S may change)
#   -n              dry run: print what would run; run and write nothing
#   SWEEP PLAN OPTIONS  bench-sph sweep's options; not --out, --resume, --shard or --force,
#                   which the script sets
# Environment (optional): BENCH_SPH, the binary (default target/release/bench-sph of this
# clone, built with cargo build --release).
#
# Without -S the shards run ONE AFTER ANOTHER, never at once: shards running together on one
# machine take each other's cores, and every timing of both would measure that contention.
# Sharding on one machine only rehearses a run across machines (or splits a long study you
# stop with Ctrl-C and continue with -r): an unsharded sweep measures the same, with one seq
# reference instead of one per shard.
#
# With -S (GNU parallel needed here; on the hosts, ssh logins that ask no password, and perl
# for GNU parallel's side of the job):
#   - each host runs one shard at a time, so no two shards share a machine;
#   - the binary is BENCH_SPH at the same absolute path on every host, and RESULTS_DIR is on
#     a filesystem that every host and this machine mount at the same path (NFS home,
#     scratch). Each shard writes its cells there as it goes, where the merge reads them, and
#     -r can continue a shard on any host. (Not parallel's --return: a shard interrupted on
#     one host could only be continued on that host, and nothing of it shows here before it
#     ends.)
#   - before anything runs every host is checked: it sees a file written here into
#     RESULTS_DIR, it has the binary, it has at least the plan's largest --cores in hardware
#     threads, and it has the same CPU model and number of hardware threads as the others
#     (merge refuses anything else: that is a comparison, for bench-sph report A B).
# The merge and the report run on this machine. After a Ctrl-C, -r continues. Make sure no
# shard still runs on a host first: its sweep's lock on the shard's directory stops a second
# sweep only where the shared filesystem supports locks.
set -euo pipefail

HERE=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
# shellcheck source=scripts/shard-job.sh
source "$HERE/shard-job.sh"
PLAN_DRIVER=parallel-sweep.sh

usage() {
    sed -n '2,/^set -euo/{/^set -euo/d;s/^# \{0,1\}//;p}' "$0"
}

# ---- Arguments ----------------------------------------------------------------------------
if [[ "${1:-}" == --help ]]; then
    usage
    exit 0
fi
K=""
OUT=""
HOSTS=""
FORCE=0
RESUME=0
DRY=0
while getopts ':k:o:S:frnh' opt; do
    case "$opt" in
    k) K=$OPTARG ;;
    o) OUT=$OPTARG ;;
    S) HOSTS=$OPTARG ;;
    f) FORCE=1 ;;
    r) RESUME=1 ;;
    n) DRY=1 ;;
    h)
        usage
        exit 0
        ;;
    :) die "-$OPTARG needs a value (try -h)" ;;
    *)
        if [[ "$OPTARG" == - ]]; then
            die "the sweep's options come after --:" \
                "scripts/parallel-sweep.sh -k K -o DIR -- --cores 1..2 ..."
        fi
        die "unknown option -$OPTARG (try -h)"
        ;;
    esac
done
shift $((OPTIND - 1))

settle_plan "$@"
if [[ -n "$HOSTS" ]]; then
    IFS=, read -r -a HOST_LIST <<<"$HOSTS"
    for host in "${HOST_LIST[@]}"; do
        [[ "$host" =~ ^[A-Za-z0-9_.:@-]+$ ]] ||
            die "-S: '$host' is not an ssh login (host or user@host;" \
                "no job counts: one shard runs on each host at a time)"
    done
fi

CPUS=""
if CORES=$(plan_value --cores "${PLAN[@]+"${PLAN[@]}"}"); then
    CPUS=$(max_cores "$CORES")
fi

BIN=${BENCH_SPH:-$(cd "$HERE/.." && pwd)/target/release/bench-sph}
[[ "$BIN" == /* ]] || BIN="$PWD/$BIN"
if [[ ! -x "$BIN" ]]; then
    if ((DRY)); then
        warn "no bench-sph binary at '$BIN' yet (cargo build --release, or BENCH_SPH=path)"
    else
        die "no bench-sph binary at '$BIN': build it with cargo build --release (or set BENCH_SPH)"
    fi
fi
# Not a pipe into grep -q: with pipefail, parallel killed by SIGPIPE would fail the test.
if [[ -n "$HOSTS" && "$(parallel --version 2>/dev/null || true)" != "GNU parallel"* ]]; then
    die "-S runs the shards with GNU parallel, which is not installed here: install the package" \
        "'parallel' (apt-get install parallel, dnf install parallel, brew install parallel;" \
        "moreutils' 'parallel' is another program)"
fi

JOB="$HERE/shard-job.sh"
# The copy of JOB that the hosts run, from the shared RESULTS_DIR (so they need no clone).
HOST_JOB="$OUT/sharding-job.sh"
SHARD_NUMBERS=()
for ((i = 1; i <= SHARDS; i++)); do SHARD_NUMBERS+=("$i"); done
# In GNU parallel: one shard at a time on each host, its lines tagged with its number as they
# come, a record of each job; -q passes every argument to the remote shell as it is.
PARALLEL_ARGS=(-j1 -S "$HOSTS" --line-buffer --tagstring 'shard {}'
    --joblog "$OUT/parallel-joblog.txt" -q)

# ---- Dry run ------------------------------------------------------------------------------
if ((DRY)); then
    echo "dry run: nothing is written or run"
    echo "$OUT/$PLAN_FILE would hold: shards=$SHARDS, then the plan: ${PLAN[*]+"${PLAN[*]}"}"
    if [[ -n "$HOSTS" ]]; then
        echo "would check each of $HOSTS" \
            "(RESULTS_DIR shared, the binary there, hardware threads, CPU model)"
        echo "would copy $JOB to $HOST_JOB"
        echo "would run: $(quote_args parallel "${PARALLEL_ARGS[@]}" bash "$HOST_JOB" shard \
            "{}/$SHARDS" "$MODE" "$BIN" "$OUT" "${PLAN[@]+"${PLAN[@]}"}" ::: "${SHARD_NUMBERS[@]}")"
        echo "so that the hosts run, one shard at a time each:"
    fi
    for i in "${SHARD_NUMBERS[@]}"; do
        SHARD_JOB_DRY_RUN=1 bash "$JOB" shard "$i/$SHARDS" "$MODE" "$BIN" "$OUT" \
            "${PLAN[@]+"${PLAN[@]}"}"
    done
    echo "then, here:"
    SHARD_JOB_DRY_RUN=1 bash "$JOB" merge "$SHARDS" "$MODE" "$BIN" "$OUT" "${PLAN[@]+"${PLAN[@]}"}"
    exit 0
fi

# ---- Checks of the machines ---------------------------------------------------------------
mkdir -p "$OUT"
if [[ -n "$HOSTS" ]]; then
    TOKEN=$(mktemp "$OUT/.parallel-sweep-check.XXXXXX")
    trap 'rm -f "$TOKEN"' EXIT
    echo "Checking $HOSTS ..."
    # The job's own text: whether RESULTS_DIR is shared is what this finds out.
    PROBES=$(parallel --nonall --tag -S "$HOSTS" -q bash -c "$(cat "$JOB")" shard-job.sh \
        probe "$BIN" "$TOKEN") ||
            die "could not run a command on every host (see above): check ssh $HOSTS"
    rm -f "$TOKEN"
    trap - EXIT
    first=""
    while IFS=$'\t' read -r host threads seen runs model; do
        [[ "$seen" == yes ]] ||
            die "$host does not see '$OUT': RESULTS_DIR must be on a filesystem that every host" \
                "mounts at the same path"
        [[ "$runs" == yes ]] ||
            die "$host has no bench-sph binary at '$BIN' (the same path on every host)"
        if [[ -n "$CPUS" && -n "$threads" ]] && ((CPUS > threads)); then
            die "--cores goes up to $CPUS, but $host has $threads hardware threads: those cells" \
                "would time threads waiting for cores"
        fi
        if [[ -z "$first" ]]; then
            first="$model, $threads hardware threads"
            first_host=$host
        elif [[ "$model, $threads hardware threads" != "$first" ]]; then
            die "$first_host has $first, $host has $model, $threads hardware threads: merge" \
                "refuses shards of different machines; that is a comparison (an unsharded sweep" \
                "on each, then bench-sph report A B)"
        fi
    done <<<"$PROBES"
    [[ -n "$first" ]] || die "no host answered the check"
    echo "Hosts: $HOSTS, each $first"
else
    threads=$(hardware_threads)
    if [[ -n "$CPUS" && -n "$threads" ]] && ((CPUS > threads)); then
        die "--cores goes up to $CPUS, but this machine has $threads hardware threads: those" \
            "cells would time threads waiting for cores"
    fi
fi
write_plan_file "$OUT" "$SHARDS" "${PLAN[@]+"${PLAN[@]}"}"
if [[ -n "$HOSTS" ]]; then
    # Renamed into place: a shard still running the old copy keeps reading that one.
    cp -f -- "$JOB" "$HOST_JOB.tmp"
    mv -f -- "$HOST_JOB.tmp" "$HOST_JOB"
fi

# ---- The shards ---------------------------------------------------------------------------
# Ctrl-C reaches the running sweeps too: each stops after its current run and keeps its
# finished cells; then no further shard starts.
FAILED=()
INTERRUPTED=0
trap 'INTERRUPTED=1' INT
if [[ -n "$HOSTS" ]]; then
    # Its exit status counts the shards that failed; the joblog names them (Seq = shard,
    # since the shards are its input in order).
    if ! parallel "${PARALLEL_ARGS[@]}" bash "$HOST_JOB" shard "{}/$SHARDS" "$MODE" "$BIN" "$OUT" \
        "${PLAN[@]+"${PLAN[@]}"}" ::: "${SHARD_NUMBERS[@]}"; then
        while IFS= read -r i; do
            FAILED+=("$i")
        done < <(awk -F'\t' 'NR > 1 && ($7 || $8) { print $1 }' "$OUT/parallel-joblog.txt")
        if ((${#FAILED[@]} == 0)); then FAILED=("(GNU parallel failed: see above)"); fi
    fi
else
    for i in "${SHARD_NUMBERS[@]}"; do
        if ! bash "$JOB" shard "$i/$SHARDS" "$MODE" "$BIN" "$OUT" "${PLAN[@]+"${PLAN[@]}"}"; then
            FAILED+=("$i")
        fi
        if ((INTERRUPTED)); then break; fi
    done
fi
trap - INT
if ((INTERRUPTED)); then
    echo "Interrupted: finished cells are kept; continue with $0 -r -o $OUT${HOSTS:+ -S $HOSTS}" >&2
    exit 130
fi
if ((${#FAILED[@]} > 0)); then
    echo "Error: shards failed: ${FAILED[*]}. Their output above says why. Continue with" >&2
    echo "  $0 -r -o $OUT${HOSTS:+ -S $HOSTS}" >&2
    echo "(complete shards are kept, a cell that failed its checksum included)," \
        "or merge what there is:" >&2
    echo "  $BIN merge $OUT/shard-[0-9]* --out $OUT/merged --allow-partial" >&2
    exit 1
fi

# ---- Merge and report ---------------------------------------------------------------------
bash "$JOB" merge "$SHARDS" "$MODE" "$BIN" "$OUT" "${PLAN[@]+"${PLAN[@]}"}"
echo "Done: the merged study is in $OUT/merged/"
