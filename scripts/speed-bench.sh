#!/usr/bin/env bash
# Speed figures of bench-sph as ratios to the plain compiled C++ all-pairs loop (issue 15),
# measured in the same run: benches/plain-loop/mueller.cpp (seed preset, N = 1000, 1000 steps)
# against `bench-sph simulate` all-pairs and grid (in index and in cell order) at that size, plus
# the grid at N = 10^4, 10^5 and 10^6 with every strategy of LARGE_STRATEGIES below, and the
# 2-core efficiency at N = 10^6 measured paired with seq (`bench-sph speedup`, PAIRED_STRATEGIES).
#
# Usage: scripts/speed-bench.sh [--runs K] [--quick] [--simd LIST] [--out FILE [--force]]
#   --runs K      runs of every configuration, 1..=100 (default 5; 2 with --quick), interleaved
#                 run by run (run 1 of every configuration, then run 2, ...), so that drift of
#                 the machine's speed hits every configuration alike
#   --quick       smoke test: fewer steps everywhere (reference 100 steps, large N 50/5/1 steps);
#                 the ratios then describe the first 100 steps only
#   --simd LIST   comma- or space-separated values of bench-sph's `simulate --simd`
#                 (portable, avx2, avx512): every bench-sph row is run once per value with
#                 `--simd X` and labelled by it (default: the flag is not passed)
#   --out FILE    also write the table to FILE (atomically: a temporary file, then mv)
#   --force       let --out replace an existing FILE
# Environment (optional): CXX (default g++), CARGO_TARGET_DIR (default target).
#
# Per configuration it prints min, median and max of wall_s (the simulation loop only, as each
# program reports it); for the N = 1000 rows the ratio plain-loop median / row median and its
# range (plain min / row max .. plain max / row min); for large N the particle-steps/s range
# (n * steps / wall_s), the parallel efficiency (seq median / (cores * median)) and, at
# N = 10^6, the peak resident memory per particle; for the paired runs the efficiency of each
# run (min, median, max) and of its median step. It checks that the plain loop ends in the
# same state as `bench-sph simulate --strategy seq` (all-pairs): same checksum.
# The paper's workload across cores: the plain loop's OpenMP build (-fopenmp; each pass's loop
# `omp parallel for schedule(static)`) on 1 .. hardware threads, its speedup (1-thread median
# over T-thread median), beside bench-sph's paired speedups (`bench-sph speedup`,
# REF_PAIRED_STRATEGIES) at each T >= 2, all-pairs, N = 1000; the OpenMP runs must end in the
# plain loop's state.
# The real workload (issue 41): the wcsph dam break of `bench-sph validate --resolution 40`
# (grid, to T = 3.4, 6382 steps) with seq and WCSPH_STRATEGIES on 2 cores: each median wall_s,
# its ratio to the plain loop's median (a machine-speed yardstick from the same run: the two do
# different work), the 2-core efficiency (seq median / (2 x median)), the peak RSS per particle,
# and that every strategy ends in seq's state.
# Without a C++ compiler the plain loop and the ratio columns are skipped; without OpenMP, the
# OpenMP anchor.
# Run it on an otherwise quiet machine: it warns when the 1-minute load exceeds half the
# hardware threads. Needs bash, cargo, awk, sort; no jq.
set -euo pipefail

# ---- What is measured -------------------------------------------------------------------
# The reference run (issue 15): seed preset, N = 1000, 1000 steps.
REF_N=1000
REF_STEPS=1000
# Its bench-sph rows: all-pairs, the grid, and the grid summing in cell order (`--order cell`:
# faster, not the seed's bits, so not compared with the plain loop's state).
REF_SEARCHES=(all-pairs grid grid-cell)
# Large-N grid runs: "N STEPS". The same 10 steps at every size, so that the fluid is in the
# same state (the dam at rest, just released) and the cost per particle-step compares memory
# behaviour alone; more steps would change the physics (a collapsing dam has more neighbours).
LARGE_SIZES=("10000 10" "100000 10" "1000000 10")
# Strategies of the large-N runs: "STRATEGY CORES CHUNKS"; "-" = the flag is not passed.
LARGE_STRATEGIES=("seq - -" "rayon-chunks 2 10" "crossbeam-pool 2 10" "crossbeam-pool 2 50")
# Paired runs (`bench-sph speedup`: the strategy and seq a step each in turn, in one process, so
# that the VM's drift slows both alike): "STRATEGY CORES CHUNKS" at PAIRED_N, PAIRED_STEPS.
PAIRED_STRATEGIES=("crossbeam-pool 2 10" "crossbeam-pool 2 50" "rayon-chunks 2 10" "rayon-chunks 2 50")
PAIRED_N=1000000
PAIRED_STEPS=10
# The paper's workload across cores (all-pairs, REF_N, REF_STEPS): bench-sph's strategies paired
# with seq at each core count from 2 to the hardware threads, "STRATEGY CHUNKS", beside the
# plain loop's OpenMP build.
REF_PAIRED_STRATEGIES=("team 8" "crossbeam-pool 4" "rayon-chunks 10")
# The wcsph rows: resolution, simulated seconds (validate's T = 3.4 at a = 1 m:
# 3.4 / sqrt(2 g / a)), and the strategies beside seq, "STRATEGY CORES CHUNKS".
WCSPH_R=40
WCSPH_T_END=0.7676
WCSPH_STRATEGIES=("team 2 8" "rayon-chunks 2 10" "crossbeam-pool 2 10")
# The N whose peak RSS per particle is reported.
RSS_N=1000000
# --quick replaces the step counts.
QUICK_REF_STEPS=100
QUICK_LARGE_SIZES=("10000 2" "100000 2" "1000000 1")
QUICK_PAIRED_STEPS=1
QUICK_WCSPH_T_END=0.05

usage() {
    sed -n '2,/^set -euo/{/^set -euo/d;s/^# \{0,1\}//;p}' "$0"
}

die() {
    echo "Error: $*" >&2
    exit 2
}

# ---- Arguments ----------------------------------------------------------------------------
RUNS=""
QUICK=0
SIMD_ARG=""
OUT=""
FORCE=0
while (($# > 0)); do
    case "$1" in
    --runs)
        (($# >= 2)) || die "--runs needs a value (1..=100)"
        RUNS="$2"
        shift 2
        ;;
    --runs=*)
        RUNS="${1#--runs=}"
        shift
        ;;
    --quick)
        QUICK=1
        shift
        ;;
    --simd)
        (($# >= 2)) || die "--simd needs a list (portable, avx2, avx512)"
        SIMD_ARG="$2"
        shift 2
        ;;
    --simd=*)
        SIMD_ARG="${1#--simd=}"
        shift
        ;;
    --out)
        (($# >= 2)) || die "--out needs a file name"
        OUT="$2"
        shift 2
        ;;
    --out=*)
        OUT="${1#--out=}"
        shift
        ;;
    --force)
        FORCE=1
        shift
        ;;
    -h | --help)
        usage
        exit 0
        ;;
    *) die "unknown argument '$1' (try --help)" ;;
    esac
done

if [[ -z "$RUNS" ]]; then
    if ((QUICK)); then RUNS=2; else RUNS=5; fi
fi
if ! [[ "$RUNS" =~ ^[0-9]{1,3}$ ]] || ((10#$RUNS < 1 || 10#$RUNS > 100)); then
    die "--runs must be a whole number from 1 to 100, not '$RUNS'"
fi
RUNS=$((10#$RUNS))

# SIMD variants; "" = no --simd flag.
SIMDS=()
for x in ${SIMD_ARG//,/ }; do
    case "$x" in
    portable | avx2 | avx512) SIMDS+=("$x") ;;
    *) die "unknown --simd value '$x' (portable, avx2 or avx512)" ;;
    esac
done
if ((${#SIMDS[@]} == 0)); then SIMDS=(""); fi

if [[ -n "$OUT" ]]; then
    [[ "$OUT" != */ ]] || die "--out needs a file name, not a folder: '$OUT'"
    if [[ -e "$OUT" || -L "$OUT" ]] && ((!FORCE)); then
        die "'$OUT' already exists (pass --force to replace it)"
    fi
    [[ ! -d "$OUT" ]] || die "'$OUT' is a folder"
    OUT_DIR="$(dirname -- "$OUT")"
    [[ -d "$OUT_DIR" && -w "$OUT_DIR" ]] || die "cannot write into the folder '$OUT_DIR'"
    # Absolute, since the script changes folder.
    OUT="$(cd -- "$OUT_DIR" && pwd)/$(basename -- "$OUT")"
fi

if ((QUICK)); then
    REF_STEPS=$QUICK_REF_STEPS
    LARGE_SIZES=("${QUICK_LARGE_SIZES[@]}")
    PAIRED_STEPS=$QUICK_PAIRED_STEPS
    WCSPH_T_END=$QUICK_WCSPH_T_END
fi

# A relative CARGO_TARGET_DIR means relative to where the script was started.
if [[ -n "${CARGO_TARGET_DIR:-}" && "$CARGO_TARGET_DIR" != /* ]]; then
    CARGO_TARGET_DIR="$PWD/$CARGO_TARGET_DIR"
    export CARGO_TARGET_DIR
fi
cd "$(dirname -- "$0")/.."
BIN="${CARGO_TARGET_DIR:-target}/release/bench-sph"
CXX="${CXX:-g++}"

WORK="$(mktemp -d "${TMPDIR:-/tmp}/speed-bench.XXXXXX")"
OUT_TMP=""
cleanup() {
    rm -rf -- "$WORK"
    if [[ -n "$OUT_TMP" ]]; then rm -f -- "$OUT_TMP"; fi
}
trap cleanup EXIT
trap 'exit 130' INT
trap 'exit 143' TERM

TABLE="$WORK/table.txt"
RESULTS="$WORK/results.txt"
: >"$TABLE"
: >"$RESULTS"
# Everything the table says goes to stdout and to $TABLE (for --out).
say() {
    printf '%s\n' "$*" | tee -a "$TABLE"
}
sayf() {
    # shellcheck disable=SC2059 # the format is the caller's
    printf "$@" | tee -a "$TABLE"
}

# ---- The machine --------------------------------------------------------------------------
THREADS="$(getconf _NPROCESSORS_ONLN 2>/dev/null || nproc 2>/dev/null || echo 1)"
say "uptime: $(uptime)"
if [[ -r /proc/loadavg ]]; then
    read -r LOAD _ </proc/loadavg
else
    # "load average(s): 0.52, 0.40, 0.33" (some locales write 0,52).
    LOAD="$(uptime | sed -n 's/.*load averages*: *\([0-9]*[.,][0-9]*\).*/\1/p' | tr , .)"
fi
if awk -v load="${LOAD:-0}" -v t="$THREADS" 'BEGIN { exit !(load > 0.5 * t) }'; then
    echo "warning: the 1-minute load is $LOAD, above 0.5 x $THREADS hardware threads:" \
        "other work is competing, so these figures are not clean" >&2
    say "warning: 1-minute load $LOAD > 0.5 x $THREADS hardware threads (figures not clean)"
fi

# ---- Builds -------------------------------------------------------------------------------
echo "building bench-sph (cargo build --release) ..." >&2
cargo build --release >&2
[[ -x "$BIN" ]] || die "no bench-sph binary at $BIN after the build"

PLAIN=""
OMP=""
if command -v -- "$CXX" >/dev/null 2>&1; then
    CXX="$CXX" scripts/build-plain-loop.sh "$WORK" >/dev/null
    PLAIN="$WORK/mueller"
    PLAIN_CXX="$("$CXX" --version 2>/dev/null | head -n 1)"
    if [[ -x "$WORK/mueller-omp" ]]; then
        OMP="$WORK/mueller-omp"
    else
        echo "skipping the OpenMP anchor" >&2
    fi
else
    echo "no C++ compiler ('$CXX' not found): skipping the plain loop and the ratio columns" >&2
fi

# ---- How a run's peak resident memory is measured -----------------------------------------
if [[ -x /usr/bin/time ]] && /usr/bin/time -f %M -o "$WORK/probe" true 2>/dev/null &&
    [[ "$(cat "$WORK/probe")" =~ ^[0-9]+$ ]]; then
    RSS_HOW="/usr/bin/time -f %M (peak RSS reported by the kernel at exit)"
    RSS_MODE=gnu-time
elif [[ -d /proc/self ]]; then
    RSS_HOW="VmHWM of /proc/PID/status polled every 0.05 s by a wrapper (a lower bound)"
    RSS_MODE=poll
else
    RSS_HOW="not measured (neither GNU /usr/bin/time nor /proc)"
    RSS_MODE=none
fi

# run_measured RSS_FILE CMD...: runs CMD with stdout as this function's stdout, writes its
# peak RSS in KiB (or "-") to RSS_FILE.
run_measured() {
    local rss_file="$1"
    shift
    case "$RSS_MODE" in
    gnu-time)
        /usr/bin/time -f %M -o "$rss_file" "$@"
        ;;
    poll)
        local pid hwm=0 v status=0
        "$@" &
        pid=$!
        while kill -0 "$pid" 2>/dev/null; do
            v="$(awk '/^VmHWM:/ { print $2 }' "/proc/$pid/status" 2>/dev/null || true)"
            if [[ -n "$v" ]]; then hwm="$v"; fi
            sleep 0.05
        done
        wait "$pid" || status=$?
        echo "$hwm" >"$rss_file"
        return "$status"
        ;;
    *)
        echo - >"$rss_file"
        "$@"
        ;;
    esac
}

json_field() {
    sed -n "s/.*\"$1\":\"\{0,1\}\([^,\"}]*\).*/\1/p"
}

# One line per run in $RESULTS: KEY WALL_S RSS_KIB CHECKSUM.
# run_one KEY CMD...
run_one() {
    local key="$1" json wall sum rss
    shift
    if ! json="$(run_measured "$WORK/rss" "$@")"; then
        echo "Error: this run failed: $*" >&2
        exit 1
    fi
    wall="$(json_field wall_s <<<"$json")"
    sum="$(json_field checksum <<<"$json")"
    rss="$(tr -d ' \n' <"$WORK/rss")"
    if [[ -z "$wall" || -z "$sum" ]]; then
        echo "Error: no wall_s/checksum in the output of: $*" >&2
        echo "  $json" >&2
        exit 1
    fi
    echo "$key $wall ${rss:--} $sum" >>"$RESULTS"
    printf '  run %d/%d  %-44s %10s s\n' "$run" "$RUNS" "$key" "$wall" >&2
}

# run_paired KEY CMD...: a `speedup --json` run; one line in $RESULTS as run_one's, with its
# efficiency in place of wall_s, and one more under step:KEY with the median of its
# step-by-step speedups over the cores.
run_paired() {
    local key="$1" json eff med sum cores
    shift
    if ! json="$("$@")"; then
        echo "Error: this run failed: $*" >&2
        exit 1
    fi
    eff="$(json_field efficiency <<<"$json")"
    med="$(json_field median <<<"$json")"
    cores="$(json_field cores <<<"$json")"
    sum="$(json_field checksum <<<"$json")"
    if [[ -z "$eff" || -z "$med" || -z "$cores" || -z "$sum" ]]; then
        echo "Error: no efficiency/median/cores/checksum in the output of: $*" >&2
        echo "  $json" >&2
        exit 1
    fi
    echo "$key $eff - $sum" >>"$RESULTS"
    echo "step:$key $(awk -v m="$med" -v c="$cores" 'BEGIN { printf "%.17g", m / c }') - $sum" \
        >>"$RESULTS"
    printf '  run %d/%d  %-44s eff %s\n' "$run" "$RUNS" "$key" "$eff" >&2
}

# Keys: plain | ref:SEARCH:SIMD | large:N:STEPS:STRATEGY:CORES:CHUNKS:SIMD ("-" = none) |
# paired:N:STEPS:STRATEGY:CORES:CHUNKS and step:paired:...
simd_flag() {
    if [[ -n "$1" ]]; then printf '%s\n' --simd "$1"; fi
}

echo "runs: $RUNS, interleaved; rows per run: plain loop, reference, large N, paired, the" \
    "paper's workload across cores" >&2
for ((run = 1; run <= RUNS; run++)); do
    if [[ -n "$PLAIN" ]]; then
        run_one plain "$PLAIN" "$REF_N" "$REF_STEPS"
    fi
    for simd in "${SIMDS[@]}"; do
        mapfile -t sflag < <(simd_flag "$simd")
        for nb in "${REF_SEARCHES[@]}"; do
            search=(--neighbors "$nb")
            if [[ "$nb" == grid-cell ]]; then search=(--neighbors grid --order cell); fi
            run_one "ref:$nb:${simd:--}" "$BIN" simulate --json --strategy seq "${search[@]}" \
                --n "$REF_N" --steps "$REF_STEPS" ${sflag[@]+"${sflag[@]}"}
        done
    done
    for size in "${LARGE_SIZES[@]}"; do
        read -r n steps <<<"$size"
        for strat in "${LARGE_STRATEGIES[@]}"; do
            read -r strategy cores chunks <<<"$strat"
            extra=()
            if [[ "$cores" != - ]]; then extra+=(--cores "$cores"); fi
            if [[ "$chunks" != - ]]; then extra+=(--chunks "$chunks"); fi
            for simd in "${SIMDS[@]}"; do
                mapfile -t sflag < <(simd_flag "$simd")
                run_one "large:$n:$steps:$strategy:$cores:$chunks:${simd:--}" "$BIN" simulate \
                    --json --strategy "$strategy" --neighbors grid --n "$n" --steps "$steps" \
                    ${extra[@]+"${extra[@]}"} ${sflag[@]+"${sflag[@]}"}
            done
        done
    done
    for strat in "seq - -" "${WCSPH_STRATEGIES[@]}"; do
        read -r strategy cores chunks <<<"$strat"
        extra=()
        if [[ "$cores" != - ]]; then extra+=(--cores "$cores" --chunks "$chunks"); fi
        run_one "wcsph:$strategy:$cores:$chunks" "$BIN" simulate --json --preset wcsph \
            --resolution "$WCSPH_R" --neighbors grid --t-end "$WCSPH_T_END" \
            --strategy "$strategy" ${extra[@]+"${extra[@]}"}
    done
    for strat in "${PAIRED_STRATEGIES[@]}"; do
        read -r strategy cores chunks <<<"$strat"
        run_paired "paired:$PAIRED_N:$PAIRED_STEPS:$strategy:$cores:$chunks" "$BIN" speedup \
            --json --strategy "$strategy" --cores "$cores" --chunks "$chunks" --neighbors grid \
            --n "$PAIRED_N" --steps "$PAIRED_STEPS"
    done
    for ((t = 1; t <= THREADS; t++)); do
        if [[ -n "$OMP" ]]; then
            run_one "omp:$t" env OMP_NUM_THREADS="$t" "$OMP" "$REF_N" "$REF_STEPS"
        fi
        if ((t >= 2)); then
            for strat in "${REF_PAIRED_STRATEGIES[@]}"; do
                read -r strategy chunks <<<"$strat"
                run_paired "refpaired:$strategy:$t:$chunks" "$BIN" speedup --json \
                    --strategy "$strategy" --cores "$t" --chunks "$chunks" \
                    --neighbors all-pairs --n "$REF_N" --steps "$REF_STEPS"
            done
        fi
    done
done

# ---- Statistics ---------------------------------------------------------------------------
# stats KEY: "min median max" of wall_s (the median of an even count is the mean of the middle
# two), then the largest peak RSS (KiB, or -) and the number of distinct checksums.
stats() {
    awk -v k="$1" '$1 == k { print $2 }' "$RESULTS" | sort -g |
        awk '{ v[NR] = $1 }
             END {
                 if (NR == 0) { print "- - -"; exit }
                 m = (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2
                 printf "%.17g %.17g %.17g\n", v[1], m, v[NR]
             }'
}
peak_rss() {
    awk -v k="$1" '$1 == k && $3 != "-" { if ($3 + 0 > m) m = $3 + 0; seen = 1 }
                   END { if (seen) print m; else print "-" }' "$RESULTS"
}
checksums() {
    awk -v k="$1" '$1 == k { print $4 }' "$RESULTS" | sort -u | tr '\n' ' ' | sed 's/ $//'
}
fmt_s() {
    awk -v v="$1" 'BEGIN { if (v == "-") print "-"; else printf "%.4f", v }'
}

# Every configuration must end in the same state on every run.
DETERMINISTIC=yes
while read -r key; do
    if [[ "$(checksums "$key")" == *" "* ]]; then
        DETERMINISTIC=no
        echo "warning: the runs of $key disagree on the checksum: $(checksums "$key")" >&2
    fi
done < <(awk '{ print $1 }' "$RESULTS" | sort -u)

# ---- The table ----------------------------------------------------------------------------
COMMIT="$(git rev-parse --short HEAD 2>/dev/null || echo '?')"
if [[ -n "$(git status --porcelain --untracked-files=no 2>/dev/null || true)" ]]; then
    COMMIT="$COMMIT (with uncommitted changes)"
fi
CPU="$(sed -n 's/^model name[[:space:]]*: *//p' /proc/cpuinfo 2>/dev/null | head -n 1)"
say ""
MODE=full
if ((QUICK)); then MODE="quick (smoke test)"; fi
say "speed-bench: $(date -u +%Y-%m-%dT%H:%M:%SZ), bench-sph $COMMIT, mode: $MODE, runs: $RUNS"
say "machine: ${CPU:-unknown CPU}, $THREADS hardware threads"
if [[ -n "$PLAIN" ]]; then
    say "plain loop: benches/plain-loop/mueller.cpp, $PLAIN_CXX, -O2 -ffp-contract=off"
else
    say "plain loop: not run (no C++ compiler '$CXX'); no ratios"
fi
say "peak RSS: $RSS_HOW"
say "wall_s: the step loop only, as each program reports it; seed preset, seed 2019"

say ""
say "Reference size: N = $REF_N, $REF_STEPS steps, seq (one thread)"
sayf '%-34s %5s %10s %10s %10s   %-26s\n' configuration runs "min s" "median s" "max s" \
    "plain/this median (range)"
PLAIN_STATS=""
if [[ -n "$PLAIN" ]]; then
    PLAIN_STATS="$(stats plain)"
    read -r pmin pmed pmax <<<"$PLAIN_STATS"
    sayf '%-34s %5s %10s %10s %10s   %-26s\n' "plain C++ loop (all-pairs)" "$RUNS" \
        "$(fmt_s "$pmin")" "$(fmt_s "$pmed")" "$(fmt_s "$pmax")" "1"
fi
for simd in "${SIMDS[@]}"; do
    for nb in "${REF_SEARCHES[@]}"; do
        key="ref:$nb:${simd:--}"
        read -r lo med hi <<<"$(stats "$key")"
        ratio="-"
        if [[ -n "$PLAIN" ]]; then
            ratio="$(awk -v pmin="$pmin" -v pmed="$pmed" -v pmax="$pmax" -v lo="$lo" \
                -v med="$med" -v hi="$hi" \
                'BEGIN { printf "%.2fx (%.2f-%.2f)", pmed / med, pmin / hi, pmax / lo }')"
        fi
        label="bench-sph seq ${nb/grid-cell/grid --order cell}${simd:+ simd=$simd}"
        sayf '%-34s %5s %10s %10s %10s   %-26s\n' "$label" "$RUNS" "$(fmt_s "$lo")" \
            "$(fmt_s "$med")" "$(fmt_s "$hi")" "$ratio"
    done
done

say ""
say "Large N: grid neighbour search"
declare -A SEQ_PER_STEP=()
sayf '%-10s %6s %-34s %5s %10s %10s %10s %24s %6s %10s\n' N steps configuration runs \
    "min s" "median s" "max s" "Mparticle-steps/s min-max" "eff" "RSS B/part"
for size in "${LARGE_SIZES[@]}"; do
    read -r n steps <<<"$size"
    for simd in "${SIMDS[@]}"; do
        seq_med=""
        for strat in "${LARGE_STRATEGIES[@]}"; do
            read -r strategy cores chunks <<<"$strat"
            key="large:$n:$steps:$strategy:$cores:$chunks:${simd:--}"
            read -r lo med hi <<<"$(stats "$key")"
            if [[ "$strategy" == seq && "$med" != - ]]; then
                seq_med="$med"
                SEQ_PER_STEP["$n${simd:+:$simd}"]="$(awk -v m="$med" -v n="$n" -v s="$steps" \
                    'BEGIN { printf "%.17g", m / (n * s) }')"
            fi
            rate="$(awk -v n="$n" -v s="$steps" -v lo="$lo" -v hi="$hi" \
                'BEGIN { printf "%.2f-%.2f", n * s / hi / 1e6, n * s / lo / 1e6 }')"
            eff="-"
            if [[ "$cores" != - && "$strategy" != seq && -n "$seq_med" ]]; then
                eff="$(awk -v s="$seq_med" -v c="$cores" -v m="$med" \
                    'BEGIN { printf "%.2f", s / (c * m) }')"
            fi
            rss="-"
            if [[ "$n" == "$RSS_N" ]]; then
                kib="$(peak_rss "$key")"
                if [[ "$kib" != - ]]; then
                    rss="$(awk -v k="$kib" -v n="$n" 'BEGIN { printf "%.0f", k * 1024 / n }')"
                fi
            fi
            label="$strategy"
            if [[ "$cores" != - ]]; then label+=" cores=$cores"; fi
            if [[ "$chunks" != - ]]; then label+=" chunks=$chunks"; fi
            if [[ -n "$simd" ]]; then label+=" simd=$simd"; fi
            sayf '%-10s %6s %-34s %5s %10s %10s %10s %24s %6s %10s\n' "$n" "$steps" "$label" \
                "$RUNS" "$(fmt_s "$lo")" "$(fmt_s "$med")" "$(fmt_s "$hi")" "$rate" "$eff" "$rss"
        done
    done
done
say "eff = seq median / (cores x median); RSS B/part = the largest peak RSS of the N = $RSS_N" \
    "runs / N"
say ""
say "The real workload: wcsph, R = $WCSPH_R (3200 fluid + 1218 wall particles), grid, to" \
    "t = $WCSPH_T_END s (validate's T = 3.4)"
sayf '%-34s %5s %10s %10s %10s %20s %6s %10s\n' configuration runs "min s" "median s" "max s" \
    "this/plain median" "eff" "RSS B/part"
# Fluid and wall particles, as the program reports them.
wcsph_json="$("$BIN" simulate --json --preset wcsph --resolution "$WCSPH_R" --steps 1)"
WCSPH_PARTICLES=$(($(json_field n <<<"$wcsph_json") + $(json_field walls <<<"$wcsph_json")))
wcsph_seq=""
for strat in "seq - -" "${WCSPH_STRATEGIES[@]}"; do
    read -r strategy cores chunks <<<"$strat"
    key="wcsph:$strategy:$cores:$chunks"
    read -r lo med hi <<<"$(stats "$key")"
    if [[ "$strategy" == seq ]]; then wcsph_seq="$med"; fi
    ratio="-"
    if [[ -n "$PLAIN" ]]; then
        ratio="$(awk -v p="$pmed" -v m="$med" 'BEGIN { printf "%.2fx", m / p }')"
    fi
    eff="-"
    if [[ "$cores" != - ]]; then
        eff="$(awk -v s="$wcsph_seq" -v c="$cores" -v m="$med" 'BEGIN { printf "%.2f", s / (c * m) }')"
    fi
    rss="$(awk -v k="$(peak_rss "$key")" -v n="$WCSPH_PARTICLES" \
        'BEGIN { if (k == "-") print "-"; else printf "%.0f", k * 1024 / n }')"
    label="$strategy"
    if [[ "$cores" != - ]]; then label+=" cores=$cores chunks=$chunks"; fi
    sayf '%-34s %5s %10s %10s %10s %20s %6s %10s\n' "$label" "$RUNS" "$(fmt_s "$lo")" \
        "$(fmt_s "$med")" "$(fmt_s "$hi")" "$ratio" "$eff" "$rss"
done
say "this/plain = median / the plain loop's median (a yardstick of the machine's speed from the"
say "same run, not the same work); eff = seq median / (cores x median); RSS B/part = the largest"
say "peak RSS / (fluid + wall particles), the whole process at this small size"
say ""
say "Paired with seq (bench-sph speedup: a step of the strategy and a step of seq in turn, one" \
    "process; grid, N = $PAIRED_N, $PAIRED_STEPS steps each; the default simd path, whatever" \
    "--simd says)"
sayf '%-34s %5s %24s %24s\n' configuration runs "efficiency min/med/max" "step-median eff min/med/max"
for strat in "${PAIRED_STRATEGIES[@]}"; do
    read -r strategy cores chunks <<<"$strat"
    key="paired:$PAIRED_N:$PAIRED_STEPS:$strategy:$cores:$chunks"
    read -r lo med hi <<<"$(stats "$key")"
    read -r slo smed shi <<<"$(stats "step:$key")"
    sayf '%-34s %5s %24s %24s\n' "$strategy cores=$cores chunks=$chunks" "$RUNS" \
        "$(awk -v a="$lo" -v b="$med" -v c="$hi" 'BEGIN { printf "%.2f/%.2f/%.2f", a, b, c }')" \
        "$(awk -v a="$slo" -v b="$smed" -v c="$shi" 'BEGIN { printf "%.2f/%.2f/%.2f", a, b, c }')"
done
say "efficiency = (sum of seq's step times) / (cores x sum of the strategy's); step-median eff ="
say "the median over the steps of (seq's step time / the strategy's) / cores; both copies end in"
say "the same checksum (speedup fails otherwise)"
# How the cost of a particle-step grows with N: seq at the largest size over seq at the smallest.
read -r first_n _ <<<"${LARGE_SIZES[0]}"
read -r last_n _ <<<"${LARGE_SIZES[-1]}"
for simd in "${SIMDS[@]}"; do
    small="${SEQ_PER_STEP["$first_n${simd:+:$simd}"]:-}"
    large="${SEQ_PER_STEP["$last_n${simd:+:$simd}"]:-}"
    if [[ -n "$small" && -n "$large" ]]; then
        say "seq time per particle-step, N = $last_n over N = $first_n${simd:+ (simd=$simd)}:" \
            "$(awk -v a="$large" -v b="$small" 'BEGIN { printf "%.2fx", a / b }') (medians)"
    fi
done

say ""
say "The paper's workload across cores: all-pairs, N = $REF_N, $REF_STEPS steps; speedup min/med/max"
say "(OpenMP: 1-thread median over each T-thread run; bench-sph: \`speedup\`, paired with seq)"
header=("OpenMP plain loop")
for strat in "${REF_PAIRED_STRATEGIES[@]}"; do
    read -r strategy chunks <<<"$strat"
    header+=("$strategy chunks=$chunks")
done
line="$(printf '%-6s' cores)"
for h in "${header[@]}"; do line+="$(printf ' %26s' "$h")"; done
say "$line"
omp1=""
if [[ -n "$OMP" ]]; then read -r _ omp1 _ <<<"$(stats omp:1)"; fi
for ((t = 1; t <= THREADS; t++)); do
    line="$(printf '%-6s' "$t")"
    cell="-"
    if [[ -n "$OMP" ]]; then
        read -r lo med hi <<<"$(stats "omp:$t")"
        cell="$(awk -v b="$omp1" -v lo="$lo" -v m="$med" -v hi="$hi" \
            'BEGIN { printf "%.2f/%.2f/%.2f", b / hi, b / m, b / lo }')"
    fi
    line+="$(printf ' %26s' "$cell")"
    for strat in "${REF_PAIRED_STRATEGIES[@]}"; do
        read -r strategy chunks <<<"$strat"
        cell="-"
        if ((t >= 2)); then
            read -r lo med hi <<<"$(stats "refpaired:$strategy:$t:$chunks")"
            cell="$(awk -v t="$t" -v lo="$lo" -v m="$med" -v hi="$hi" \
                'BEGIN { printf "%.2f/%.2f/%.2f", t * lo, t * m, t * hi }')"
        fi
        line+="$(printf ' %26s' "$cell")"
    done
    say "$line"
done

# ---- Checks -------------------------------------------------------------------------------
say ""
SAME_ALL=yes
if [[ -n "$PLAIN" ]]; then
    plain_sum="$(checksums plain)"
    for simd in "${SIMDS[@]}"; do
        ref_sum="$(checksums "ref:all-pairs:${simd:--}")"
        same=no
        if [[ "$plain_sum" == "$ref_sum" ]]; then same=yes; else SAME_ALL=no; fi
        say "plain loop computes the same state${simd:+ (simd=$simd)}: $same" \
            "(plain $plain_sum, bench-sph seq all-pairs $ref_sum)"
    done
else
    say "plain loop computes the same state: not checked (no C++ compiler)"
fi
if [[ -n "$OMP" ]]; then
    omp_same=yes
    for ((t = 1; t <= THREADS; t++)); do
        if [[ "$(checksums "omp:$t")" != "$(checksums plain)" ]]; then
            omp_same=no
            SAME_ALL=no
        fi
    done
    say "the OpenMP build computes the plain loop's state on 1 .. $THREADS threads: $omp_same"
fi
# Strategies must agree with seq bit for bit at every size.
AGREE=yes
for size in "${LARGE_SIZES[@]}"; do
    read -r n steps <<<"$size"
    for simd in "${SIMDS[@]}"; do
        sums="$(for strat in "${LARGE_STRATEGIES[@]}"; do
            read -r strategy cores chunks <<<"$strat"
            checksums "large:$n:$steps:$strategy:$cores:$chunks:${simd:--}"
            echo
        done | sort -u | grep -c .)"
        if [[ "$sums" != 1 ]]; then
            AGREE=no
            echo "warning: the strategies disagree at N = $n${simd:+ simd=$simd}" >&2
        fi
    done
done
sums="$(for strat in "seq - -" "${WCSPH_STRATEGIES[@]}"; do
    read -r strategy cores chunks <<<"$strat"
    checksums "wcsph:$strategy:$cores:$chunks"
    echo
done | sort -u | grep -c .)"
if [[ "$sums" != 1 ]]; then
    AGREE=no
    echo "warning: the strategies disagree on the wcsph run" >&2
fi
say "large-N and wcsph strategies agree with seq bit for bit: $AGREE; every configuration repeats its" \
    "checksum run to run: $DETERMINISTIC"
say "uptime: $(uptime)"

# ---- --out --------------------------------------------------------------------------------
if [[ -n "$OUT" ]]; then
    OUT_TMP="$(mktemp "$(dirname -- "$OUT")/.speed-bench.XXXXXX")"
    cat "$TABLE" >"$OUT_TMP"
    chmod 644 "$OUT_TMP"
    if ((FORCE)); then
        mv -f -- "$OUT_TMP" "$OUT"
    else
        # -n never replaces a file that appeared while the benchmark ran.
        mv -n -- "$OUT_TMP" "$OUT" 2>/dev/null || true
        if [[ -e "$OUT_TMP" ]]; then
            echo "Error: '$OUT' appeared while the benchmark ran; the table is only on stdout" >&2
            exit 1
        fi
    fi
    OUT_TMP=""
    echo "wrote $OUT" >&2
fi

if [[ "$SAME_ALL" != yes || "$AGREE" != yes || "$DETERMINISTIC" != yes ]]; then
    echo "Error: the runs did not all compute the same state (see above)" >&2
    exit 1
fi
