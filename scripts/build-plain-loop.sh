#!/usr/bin/env bash
# Builds the plain C++ loop (benches/plain-loop/mueller.cpp): DIR/mueller, the serial loop that
# the speed figures are ratios to, and DIR/mueller-omp, its OpenMP build (each pass
# `omp parallel for schedule(static)`), the anchor of `bench-sph sweep --anchor` and of
# scripts/speed-bench.sh. Both without fused multiply-adds (-ffp-contract=off), so that they
# end in bench-sph's state bit for bit.
#
# Usage: scripts/build-plain-loop.sh [DIR]      (default DIR: target/plain-loop)
# Environment: CXX (default g++).
# Prints the path of each program built, one a line; exits 1 without a C++ compiler. Without
# OpenMP it builds the serial loop alone and says so on stderr.
set -euo pipefail

DIR="${1:-target/plain-loop}"
CXX="${CXX:-g++}"
SOURCE="$(dirname "$0")/../benches/plain-loop/mueller.cpp"
FLAGS=(-O2 -ffp-contract=off -std=c++17)

if ! command -v -- "$CXX" >/dev/null 2>&1; then
    echo "Error: no C++ compiler ('$CXX' not found); set CXX to one" >&2
    exit 1
fi
mkdir -p "$DIR"
# Each program is written under a temporary name and renamed, so a failed build leaves the
# last good one (or none).
build() {
    local out="$1"
    shift
    "$CXX" "${FLAGS[@]}" "$@" -o "$out.tmp.$$" "$SOURCE" && mv -f "$out.tmp.$$" "$out"
}
echo "compiling $SOURCE with $CXX ${FLAGS[*]} ..." >&2
build "$DIR/mueller"
echo "$DIR/mueller"
if build "$DIR/mueller-omp" -fopenmp 2>/dev/null; then
    echo "$DIR/mueller-omp"
else
    rm -f "$DIR/mueller-omp.tmp.$$"
    echo "'$CXX' cannot build with -fopenmp: no OpenMP build" >&2
fi
