#!/usr/bin/env bash
# One piece of a sharded sweep (book/src/commands/merge.md): the job that slurm-sweep.sh submits
# and parallel-sweep.sh runs for every shard, kept in one file so that both follow one rule.
# Not usually called by hand, but it can be, e.g. to run one shard again.
#
# Usage: scripts/shard-job.sh shard I/K MODE BIN RESULTS_DIR [SWEEP PLAN OPTIONS...]
#        scripts/shard-job.sh merge K MODE BIN RESULTS_DIR [SWEEP PLAN OPTIONS...]
#        scripts/shard-job.sh probe BIN FILE
#   shard   runs shard I of K: BIN sweep PLAN --shard I/K --out RESULTS_DIR/shard-I --no-plots
#           (the report is drawn once, from the merged shards). I = `array` is the Slurm array
#           task's number ($SLURM_ARRAY_TASK_ID).
#   merge   BIN merge RESULTS_DIR/shard-1 ... shard-K --out RESULTS_DIR/merged, then
#           BIN report RESULTS_DIR/merged (not when the plan has --no-plots)
#   probe   prints one tab-separated line about this machine, for parallel-sweep.sh's checks:
#           hardware threads, whether FILE and BIN are there (yes/no), the CPU model
#   MODE    new     a fresh shard (the sweep refuses a directory that holds results)
#           force   replaces earlier results (sweep --force, merge --force)
#           resume  a complete shard is kept as it is (failed cells included), an unfinished
#                   one continues with `sweep --resume`, a missing one starts; merge --force
# Environment: SHARD_JOB_DRY_RUN=1 prints the commands instead of running them.
#
# A shard refuses to start when the plan's largest --cores exceeds the hardware threads this
# process may use: those cells would time threads queueing for cores, not the strategy.
# Sourced (by slurm-sweep.sh and parallel-sweep.sh), it only defines its functions.
set -euo pipefail

# The most shards a sweep takes (bench-sph sweep --shard I/K: 1 <= I <= K <= 1024).
MAX_SHARDS=1024
# The most worker threads a sweep takes (harness/src/limits.rs).
MAX_CORES=1024
# The record of a sharded sweep in its results directory: written when it starts, read by -r.
PLAN_FILE=sharding.txt

die() {
    echo "Error: $*" >&2
    exit 2
}

warn() {
    echo "warning: $*" >&2
}

# Checks that $1 is a shard count, 1..MAX_SHARDS ($2 says where it came from).
check_shard_count() {
    if ! [[ "$1" =~ ^[1-9][0-9]{0,3}$ ]] || ((10#$1 > MAX_SHARDS)); then
        die "$2 must be a whole number from 1 to $MAX_SHARDS, not '$1'"
    fi
}

# Refuses what a sharded sweep's plan options must not hold: what the scripts set themselves,
# a forgotten `--` (a subcommand or the binary first), a line break (the plan file is one
# option per line).
check_plan() {
    local arg
    if (($# > 0)) && [[ "$1" != -* ]]; then
        die "'$1': after -- come bench-sph sweep's options only (e.g. -- --cores 1..16 --n" \
            "10000), without 'sweep' or the binary"
    fi
    for arg in "$@"; do
        case "$arg" in
        --out | --out=* | --resume | --resume=* | --shard | --shard=* | --force)
            die "${arg%%=*} is the script's to set: shards go to RESULTS_DIR/shard-I; -f replaces" \
                "an earlier sweep, -r continues one"
            ;;
        *$'\n'*) die "an option with a line break: '$arg'" ;;
        esac
    done
}

# Prints the value of option $1 (`--opt V` or `--opt=V`, the last one counts) in the plan
# options that follow; fails when it is not there.
plan_value() {
    local option=$1 value="" found=1
    shift
    while (($# > 0)); do
        case "$1" in
        "$option")
            (($# >= 2)) || die "$option needs a value"
            value=$2
            found=0
            shift
            ;;
        "$option"=*)
            value=${1#*=}
            found=0
            ;;
        esac
        shift
    done
    if ((found == 0)); then
        printf '%s\n' "$value"
    fi
    return "$found"
}

# Whether flag $1 is among the plan options that follow.
plan_has() {
    local flag=$1 arg
    shift
    for arg in "$@"; do
        if [[ "$arg" == "$flag" ]]; then
            return 0
        fi
    done
    return 1
}

# The largest worker-thread count of a --cores RANGE (items N, A..B, A..B:S, comma-separated,
# as bench-sph reads them: A..B:S ends at the last value that does not exceed B).
max_cores() {
    local spec=$1 item max=0 last a b s items=()
    local single='^([0-9]{1,7})$' range='^([0-9]{1,7})\.\.([0-9]{1,7})(:([0-9]{1,7}))?$'
    IFS=, read -r -a items <<<"$spec"
    ((${#items[@]} > 0)) || die "--cores is empty"
    for item in "${items[@]}"; do
        if [[ "$item" =~ $single ]]; then
            last=$((10#${BASH_REMATCH[1]}))
        elif [[ "$item" =~ $range ]]; then
            a=$((10#${BASH_REMATCH[1]}))
            b=$((10#${BASH_REMATCH[2]}))
            s=$((10#${BASH_REMATCH[4]:-1}))
            ((s >= 1 && a <= b)) ||
                die "--cores '$spec': '$item' is not a range A..B or A..B:S with A <= B and S >= 1"
            last=$((a + (b - a) / s * s))
        else
            die "--cores '$spec': '$item' is not N, A..B or A..B:S"
        fi
        ((last >= 1)) || die "--cores '$spec': 0 cores"
        if ((last > max)); then
            max=$last
        fi
    done
    ((max <= MAX_CORES)) ||
        die "--cores '$spec' goes up to $max; bench-sph sweep takes at most $MAX_CORES"
    echo "$max"
}

# Hardware threads this process may use, or nothing when unknown: nproc (its CPU affinity
# mask, as bench-sph's meta.json counts them, short of cgroup CPU quotas) without the OpenMP
# variables that nproc would otherwise obey.
hardware_threads() {
    env -u OMP_NUM_THREADS -u OMP_THREAD_LIMIT nproc 2>/dev/null ||
        getconf _NPROCESSORS_ONLN 2>/dev/null || true
}

# The CPU model as bench-sph's meta.json names it: the first non-empty `model name` of
# /proc/cpuinfo, else `Hardware`, `Processor` or `cpu model`; `unknown` without one.
cpu_model() {
    awk -F: '
        function trim(s) { gsub(/^[ \t]+|[ \t]+$/, "", s); return s }
        {
            key = trim($1); value = trim(substr($0, index($0, ":") + 1))
            if (value != "" && !(key in seen)) seen[key] = value
        }
        END {
            n = split("model name|Hardware|Processor|cpu model", keys, "|")
            for (i = 1; i <= n; i++) if (keys[i] in seen) { print seen[keys[i]]; exit }
            print "unknown"
        }' /proc/cpuinfo 2>/dev/null || echo unknown
}

# Whether the sweep in directory $1 is complete: meta.json's top-level "status" (serde_json's
# pretty printer indents top-level keys by two spaces; each session's own status is deeper).
is_complete() {
    grep -q '^  "status": "complete"' "$1/meta.json" 2>/dev/null
}

# Refuses a results directory that already holds a sharded sweep, unless $2 is 1 (-f); then
# warns about shard directories above the new count $3, which the merge will not read.
check_results_dir() {
    local dir=$1 force=$2 shards=$3 had found=() count=0 stale=() d name list
    [[ ! -e "$dir" || -d "$dir" ]] || die "'$dir' exists and is not a directory"
    for d in "$dir/$PLAN_FILE" "$dir/merged"; do
        if [[ -e "$d" ]]; then found+=("${d##*/}"); fi
    done
    had=$(shopt -p nullglob || true)
    shopt -s nullglob
    for d in "$dir"/shard-[0-9]*; do
        name=${d##*/}
        count=$((count + 1))
        if [[ "$name" =~ ^shard-([0-9]+)$ ]] && ((10#${BASH_REMATCH[1]} > shards)); then
            stale+=("$name")
        fi
    done
    eval "$had"
    if ((count > 0)); then found+=("$count shard directories"); fi
    if ((${#found[@]} == 0)); then
        return 0
    fi
    if ((force == 0)); then
        printf -v list '%s, ' "${found[@]}"
        die "'$dir' already holds a sharded sweep (${list%, }):" \
            "continue it with -r, or replace it with -f"
    fi
    if ((${#stale[@]} > 0)); then
        warn "${stale[*]} in '$dir' are left from an earlier sweep with more shards: the merge" \
            "will not read them"
    fi
}

# Settles the options both drivers share once getopts is done (OUT, K, FORCE, RESUME set; the
# plan options in "$@"): OUT made absolute (the jobs and the shards' meta.json see one path),
# -f and -r exclusive, and SHARDS, PLAN and MODE (new, force, resume) from -k and the plan
# options, or from the plan file with -r.
# shellcheck disable=SC2034,SC2153 # MODE is read by the drivers; they set FORCE, RESUME, K, OUT
settle_plan() {
    [[ -n "$OUT" ]] || die "-o RESULTS_DIR is required (try -h)"
    ((!(FORCE && RESUME))) ||
        die "-f and -r exclude each other: -f starts the sweep over, -r continues it"
    [[ "$OUT" == /* ]] || OUT="$PWD/$OUT"
    while [[ "$OUT" == */ && "$OUT" != / ]]; do OUT=${OUT%/}; done
    if ((RESUME)); then
        [[ -z "$K" ]] || die "-r takes K from $OUT/$PLAN_FILE: leave out -k"
        (($# == 0)) || die "-r takes the plan from $OUT/$PLAN_FILE: give no sweep options"
        read_plan_file "$OUT"
        MODE=resume
    else
        [[ -n "$K" ]] || die "-k K is required (try -h)"
        check_shard_count "$K" "-k"
        SHARDS=$((10#$K))
        PLAN=("$@")
        check_plan "${PLAN[@]+"${PLAN[@]}"}"
        check_results_dir "$OUT" "$FORCE" "$SHARDS"
        MODE=new
        if ((FORCE)); then MODE=force; fi
    fi
}

# Writes the plan file of results directory $1: shard count $2, then the plan options, one a
# line ($PLAN_DRIVER names the script that wrote it).
write_plan_file() {
    local file="$1/$PLAN_FILE" shards=$2 arg
    shift 2
    {
        echo "# bench-sph sharded sweep (scripts/${PLAN_DRIVER:-?}): the number of shards, then"
        echo "# bench-sph sweep's plan options, one a line. The scripts' -r reads them back."
        echo "shards=$shards"
        for arg in "$@"; do
            printf '%s\n' "$arg"
        done
    } >"$file.tmp"
    mv -f -- "$file.tmp" "$file"
}

# Reads the plan file of results directory $1 into SHARDS and PLAN.
read_plan_file() {
    local file="$1/$PLAN_FILE" line n=0
    [[ -f "$file" ]] ||
        die "there is no '$file': -r continues a sharded sweep that slurm-sweep.sh or" \
            "parallel-sweep.sh started in that directory"
    SHARDS=""
    PLAN=()
    while IFS= read -r line || [[ -n "$line" ]]; do
        n=$((n + 1))
        if ((n <= 2)); then
            continue
        elif ((n == 3)); then
            [[ "$line" == shards=* ]] || die "'$file', line 3: expected shards=K, found '$line'"
            SHARDS=${line#shards=}
        else
            PLAN+=("$line")
        fi
    done <"$file"
    check_shard_count "$SHARDS" "shards= in '$file'"
}

# Prints its arguments as one shell command line, quoting only the words that need it.
quote_args() {
    local arg line="" plain='^[A-Za-z0-9_./:=@%+,-]+$' q="'"
    for arg in "$@"; do
        if [[ ! "$arg" =~ $plain ]]; then
            arg="'${arg//$q/$q\\$q$q}'"
        fi
        line+=" $arg"
    done
    printf '%s\n' "${line# }"
}

# Prints a command, then runs it (only prints it when SHARD_JOB_DRY_RUN=1).
run() {
    if [[ "${SHARD_JOB_DRY_RUN:-0}" == 1 ]]; then
        echo "would run: $(quote_args "$@")"
    else
        echo "+ $(quote_args "$@")" >&2
        "$@"
    fi
}

# shard I/K MODE BIN RESULTS_DIR [PLAN...]
shard_command() {
    local spec=$1 mode=$2 bin=$3 results=$4 i k dir threads cores max args
    shift 4
    [[ "$spec" == */* ]] || die "'$spec' is not I/K"
    i=${spec%%/*}
    k=${spec#*/}
    if [[ "$i" == array ]]; then
        i=${SLURM_ARRAY_TASK_ID:-}
        [[ -n "$i" ]] ||
            die "shard array/$k needs \$SLURM_ARRAY_TASK_ID: run it as a Slurm array task"
    fi
    check_shard_count "$k" "K of shard $spec"
    check_shard_count "$i" "I of shard $spec"
    ((10#$i <= 10#$k)) || die "shard $i/$k: I must not exceed K"
    i=$((10#$i))
    k=$((10#$k))
    case "$mode" in
    new | force | resume) ;;
    *) die "MODE must be new, force or resume, not '$mode'" ;;
    esac
    dir="$results/shard-$i"

    if [[ "${SHARD_JOB_DRY_RUN:-0}" != 1 ]]; then
        [[ -x "$bin" ]] || die "no bench-sph binary at '$bin' on $(uname -n)"
        threads=$(hardware_threads)
        echo "shard $i/$k on $(uname -n): ${threads:-unknown} hardware threads, $(cpu_model)"
        if cores=$(plan_value --cores "$@"); then
            max=$(max_cores "$cores")
            if [[ -z "$threads" ]]; then
                warn "cannot count this machine's hardware threads:" \
                    "--cores up to $max is not checked"
            elif ((max > threads)); then
                die "shard $i/$k: --cores goes up to $max, but $(uname -n) gives this process" \
                    "$threads hardware threads: those cells would time threads waiting for cores," \
                    "not the strategy"
            fi
        fi
    fi

    if [[ "$mode" == resume && -f "$dir/meta.json" ]]; then
        if is_complete "$dir"; then
            echo "shard $i/$k: '$dir' is complete; kept as it is"
            return 0
        fi
        run "$bin" sweep --resume "$dir" --no-plots
        return
    fi
    args=(sweep "$@" --shard "$i/$k" --out "$dir")
    if ! plan_has --no-plots "$@"; then
        args+=(--no-plots)
    fi
    if [[ "$mode" == force ]]; then
        args+=(--force)
    fi
    run "$bin" "${args[@]}"
}

# merge K MODE BIN RESULTS_DIR [PLAN...]
merge_command() {
    local k=$1 mode=$2 bin=$3 results=$4 i args
    shift 4
    check_shard_count "$k" "K"
    args=(merge)
    for ((i = 1; i <= 10#$k; i++)); do
        args+=("$results/shard-$i")
    done
    args+=(--out "$results/merged")
    case "$mode" in
    new) ;;
    force | resume) args+=(--force) ;;
    *) die "MODE must be new, force or resume, not '$mode'" ;;
    esac
    if [[ "${SHARD_JOB_DRY_RUN:-0}" != 1 ]]; then
        [[ -x "$bin" ]] || die "no bench-sph binary at '$bin' on $(uname -n)"
    fi
    run "$bin" "${args[@]}"
    if plan_has --no-plots "$@"; then
        echo "report: not drawn (--no-plots); draw it with: $bin report $results/merged"
    else
        run "$bin" report "$results/merged"
    fi
}

# probe BIN FILE
probe_command() {
    local bin=$1 file=$2 seen=no runs=no
    if [[ -e "$file" ]]; then seen=yes; fi
    if [[ -x "$bin" ]]; then runs=yes; fi
    printf '%s\t%s\t%s\t%s\n' "$(hardware_threads)" "$seen" "$runs" "$(cpu_model)"
}

shard_job_main() {
    local usage="usage: shard-job.sh shard I/K MODE BIN RESULTS_DIR [PLAN...]"
    usage+=" | merge K MODE BIN RESULTS_DIR [PLAN...] | probe BIN FILE"
    (($# >= 1)) || die "$usage"
    local command=$1
    shift
    case "$command" in
    shard)
        (($# >= 4)) || die "$usage"
        shard_command "$@"
        ;;
    merge)
        (($# >= 4)) || die "$usage"
        merge_command "$@"
        ;;
    probe)
        (($# == 2)) || die "$usage"
        probe_command "$@"
        ;;
    -h | --help)
        if [[ -f "$0" ]]; then
            sed -n '2,/^set -euo/{/^set -euo/d;s/^# \{0,1\}//;p}' "$0"
        else
            echo "$usage"
        fi
        ;;
    *) die "unknown command '$command' ($usage)" ;;
    esac
}

# Run (as a script, a Slurm batch job or `bash -c`), not sourced: do the work.
if [[ "${BASH_SOURCE[0]:-$0}" == "$0" ]]; then
    shard_job_main "$@"
fi
