#!/usr/bin/env bash
# Runs a bench-sph sweep on a Slurm cluster as K shards, one array task and one whole node per
# shard, then a job that merges the shards and draws the report (book/src/commands/merge.md).
# Run it on the login node, in a clone on a filesystem the compute nodes share (home,
# scratch), after `cargo build --release`.
#
# Usage: scripts/slurm-sweep.sh -k K -o RESULTS_DIR [-p PARTITION] [-t TIME] [-C FEATURE]
#                               [-f | -r] [-n] -- SWEEP PLAN OPTIONS
#   -k K            shards, 1..1024: array tasks 1..K, task I runs
#                   bench-sph sweep PLAN --shard I/K --out RESULTS_DIR/shard-I
#   -o RESULTS_DIR  on the shared filesystem; it gets shard-1 .. shard-K, merged/ (the merged
#                   results and REPORT.md), slurm/ (job logs and the binary the jobs run) and
#                   sharding.txt (K and the plan, for -r)
#   -p PARTITION    sbatch --partition of every job
#   -t TIME         sbatch --time of each shard (Slurm's formats: 90, 1:30:00, 2-00:00:00)
#   -C FEATURE      sbatch --constraint of the shards: one node type where a partition mixes
#   -f              RESULTS_DIR may hold an earlier sharded sweep: it is replaced
#   -r              submit the sharded sweep in RESULTS_DIR again, after a task failed or ran
#                   out of time: complete shards are kept, unfinished ones continue with
#                   `sweep --resume`, with the binary of the first submission; K and the plan
#                   come from RESULTS_DIR/sharding.txt (-p, -t, -C may change)
#   -n              dry run: print the sbatch commands; submit and write nothing
#   SWEEP PLAN OPTIONS  bench-sph sweep's options, --cores included (the plan must not depend
#                   on the node; its largest value is each task's --cpus-per-task); not
#                   --out, --resume, --shard or --force, which the script sets
# Environment (all optional): SBATCH, the submit command (default sbatch; it may carry
#   options: SBATCH="sbatch --account=proj"; SBATCH=echo is a dry run, like -n); sbatch's own
#   variables (SBATCH_ACCOUNT, SBATCH_QOS, ...) apply to every job as usual; BENCH_SPH, the
#   binary (default target/release/bench-sph of this clone); MERGE_TIME, sbatch --time of
#   the merge job (default 30, minutes).
#
# Why one shard per node: a shard's times are worth merging only if nothing else ran on its
# cores. Each task takes a whole node (--exclusive, one task, --mem=0), so no other job and no
# other shard shares it: two shards on one node would take each other's cores and both would
# time the contention, not the strategies. --cores must not exceed a node's hardware threads
# (the task refuses to start otherwise: those cells would time threads waiting for cores).
# The nodes must be identical (merge refuses different CPU models or thread counts: that is a
# comparison, for bench-sph report A B), so keep to a partition of one node type, or pin one
# with -C.
#
# Jobs: the array bench-sph-shard, then bench-sph-merge (1 CPU) with --dependency=afterok on
# the array, so it starts once every shard has succeeded, and --kill-on-invalid-dep=yes, so
# Slurm cancels it when one has not. The jobs run RESULTS_DIR/slurm/bench-sph, a copy of the
# binary taken at submission: a rebuild while they queue cannot mix builds, which merge would
# refuse. When a task fails or runs out of time, read RESULTS_DIR/slurm/shard-I-JOBID.out,
# then run this script with -r -o RESULTS_DIR (and a longer -t). A shard that ends non-zero
# because a cell failed its checksum is complete: -r keeps it, and the merged study lists the
# cell as failed. A shard with no cells (K above the plan's non-reference cells) is an error.
# Clusters that keep Slurm's default MaxArraySize (1001) take K <= 1000.
set -euo pipefail

HERE=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
# shellcheck source=scripts/shard-job.sh
source "$HERE/shard-job.sh"
PLAN_DRIVER=slurm-sweep.sh

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
PARTITION=""
TIME=""
FEATURE=""
FORCE=0
RESUME=0
DRY=0
while getopts ':k:o:p:t:C:frnh' opt; do
    case "$opt" in
    k) K=$OPTARG ;;
    o) OUT=$OPTARG ;;
    p) PARTITION=$OPTARG ;;
    t) TIME=$OPTARG ;;
    C) FEATURE=$OPTARG ;;
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
                "scripts/slurm-sweep.sh -k K -o DIR -- --cores 1..16 ..."
        fi
        die "unknown option -$OPTARG (try -h)"
        ;;
    esac
done
shift $((OPTIND - 1))

settle_plan "$@"
[[ -z "$PARTITION" || "$PARTITION" =~ ^[A-Za-z0-9_.,-]+$ ]] ||
    die "-p '$PARTITION' is not a partition name"
TIME_RE='^([0-9]+-)?[0-9]+(:[0-9]+){0,2}$|^(UNLIMITED|INFINITE|unlimited|infinite)$'
[[ -z "$TIME" || "$TIME" =~ $TIME_RE ]] ||
    die "-t '$TIME' is not a Slurm time (minutes, MM:SS, HH:MM:SS, D-HH, D-HH:MM or D-HH:MM:SS)"
MERGE_TIME=${MERGE_TIME:-30}
[[ "$MERGE_TIME" =~ $TIME_RE ]] ||
    die "MERGE_TIME='$MERGE_TIME' is not a Slurm time"

JOB_BIN="$OUT/slurm/bench-sph"
if ((RESUME)); then
    [[ -x "$JOB_BIN" ]] ||
        die "there is no '$JOB_BIN': -r continues a sweep that this script submitted"
fi
CORES=$(plan_value --cores "${PLAN[@]+"${PLAN[@]}"}") ||
    die "give the plan's --cores: each task needs --cpus-per-task, and without --cores" \
        "each node would plan 1..its own hardware threads"
CPUS=$(max_cores "$CORES")

# The submit command; `echo` (or -n) makes it a dry run.
read -r -a SUBMIT <<<"${SBATCH:-sbatch}"
((${#SUBMIT[@]} > 0)) || die "SBATCH is empty"
if [[ "${SUBMIT[0]}" == echo ]]; then
    DRY=1
    SUBMIT=("${SUBMIT[@]:1}")
    ((${#SUBMIT[@]} > 0)) || SUBMIT=(sbatch)
fi
if ((!DRY)); then
    command -v "${SUBMIT[0]}" >/dev/null ||
        die "'${SUBMIT[0]}' not found: run this on a Slurm login node" \
            "(-n, or SBATCH=echo, for a dry run)"
fi

if ((!RESUME)); then
    SRC_BIN=${BENCH_SPH:-$(cd "$HERE/.." && pwd)/target/release/bench-sph}
    [[ "$SRC_BIN" == /* ]] || SRC_BIN="$PWD/$SRC_BIN"
    if [[ ! -x "$SRC_BIN" ]]; then
        if ((DRY)); then
            warn "no bench-sph binary at '$SRC_BIN' yet (cargo build --release, or BENCH_SPH=path)"
        else
            die "no bench-sph binary at '$SRC_BIN':" \
                "build it with cargo build --release (or set BENCH_SPH)"
        fi
    fi
fi

# ---- Submission ---------------------------------------------------------------------------
# Submits one job: submit PLACEHOLDER SBATCH_ARGUMENTS... sets JOB_ID, or says why not and
# fails; a dry run prints the command and sets JOB_ID to PLACEHOLDER.
submit() {
    local placeholder=$1 out
    shift
    if ((DRY)); then
        echo "would submit: $(quote_args "${SUBMIT[@]}" --parsable "$@")"
        JOB_ID=$placeholder
        return 0
    fi
    if ! out=$("${SUBMIT[@]}" --parsable "$@"); then
        echo "Error: ${SUBMIT[*]} refused the job (see above)" >&2
        return 1
    fi
    JOB_ID=${out%%;*} # --parsable prints "id" or "id;cluster"
    if [[ ! "$JOB_ID" =~ ^[0-9]+$ ]]; then
        echo "Error: ${SUBMIT[*]} printed '$out', not a job id" >&2
        return 1
    fi
}

if ((DRY)); then
    echo "dry run: nothing is written or submitted"
    echo "$OUT/$PLAN_FILE would hold: shards=$SHARDS, then the plan: ${PLAN[*]}"
else
    mkdir -p "$OUT/slurm"
    if ((!RESUME)); then
        cp -f -- "$SRC_BIN" "$JOB_BIN.tmp"
        mv -f -- "$JOB_BIN.tmp" "$JOB_BIN"
        write_plan_file "$OUT" "$SHARDS" "${PLAN[@]}"
    fi
fi

COMMON=()
if [[ -n "$PARTITION" ]]; then COMMON+=(--partition="$PARTITION"); fi
SHARD_OPTS=(--job-name=bench-sph-shard --array="1-$SHARDS" --nodes=1 --ntasks=1 --exclusive
    --mem=0 --cpus-per-task="$CPUS" --chdir="$OUT" --output="$OUT/slurm/shard-%a-%A.out")
if [[ -n "$TIME" ]]; then SHARD_OPTS+=(--time="$TIME"); fi
if [[ -n "$FEATURE" ]]; then SHARD_OPTS+=(--constraint="$FEATURE"); fi

submit ARRAY_JOB_ID "${SHARD_OPTS[@]}" "${COMMON[@]+"${COMMON[@]}"}" \
    "$HERE/shard-job.sh" shard "array/$SHARDS" "$MODE" "$JOB_BIN" "$OUT" "${PLAN[@]}" || exit 1
ARRAY_ID=$JOB_ID
MERGE=("$HERE/shard-job.sh" merge "$SHARDS" "$MODE" "$JOB_BIN" "$OUT" "${PLAN[@]}")
if ! submit MERGE_JOB_ID --job-name=bench-sph-merge --dependency="afterok:$ARRAY_ID" \
    --kill-on-invalid-dep=yes --nodes=1 --ntasks=1 --cpus-per-task=1 --time="$MERGE_TIME" \
    --chdir="$OUT" --output="$OUT/slurm/merge-%j.out" "${COMMON[@]+"${COMMON[@]}"}" \
    "${MERGE[@]}"; then
    echo "The shards were submitted as job array $ARRAY_ID, the merge was not." >&2
    echo "Once every shard has succeeded (sacct -j $ARRAY_ID), merge and draw the report with" >&2
    echo "  bash $(quote_args "${MERGE[@]}")" >&2
    exit 1
fi
MERGE_ID=$JOB_ID

if ((DRY)); then
    exit 0
fi
cat <<EOF
Submitted $SHARDS shards as job array $ARRAY_ID (a whole node each, up to $CPUS cores) and
the merge as job $MERGE_ID, which starts when every shard has succeeded.
  watch:   squeue -j $ARRAY_ID,$MERGE_ID
  logs:    $OUT/slurm/
  results: $OUT/merged/ (REPORT.md) once job $MERGE_ID has run
If a shard fails or runs out of time, Slurm cancels job $MERGE_ID; then read its log and run
  $0 -r -o $OUT [-t LONGER]
EOF
