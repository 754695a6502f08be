#!/bin/sh
# Builds bench_eval_libfive.cpp against a libfive build kept outside this repository and runs it:
# frepfarm's batch evaluator (float, double) vs libfive's ArrayEvaluator, points/s and ratios.
# Optional, not part of CI. libfive built as in bench_mesh_libfive.py's docstring; frep_core
# built in $FREP_BUILD (default: build/ next to this folder).
#   usage: bench/bench_eval_libfive.sh [points] [rounds]
set -e
HERE=$(cd "$(dirname "$0")" && pwd)
ROOT=$(dirname "$HERE")
SRC=${LIBFIVE_SRC:-/work/peers/libfive-src}
BUILD=${LIBFIVE_BUILD:-/work/peers/libfive-build}
FREP_BUILD=${FREP_BUILD:-$ROOT/build}
lib=$BUILD/libfive/src/libfive.so
if [ ! -f "$lib" ] || [ ! -d "$SRC/libfive/include" ]; then
  echo "libfive not found ($lib, $SRC/libfive/include): nothing measured."
  exit 0
fi
core=$FREP_BUILD/core/libfrep_core.a
[ -f "$core" ] || { echo "missing $core: build the frep_core target first" >&2; exit 1; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
# -march=native like libfive's own build: its Eigen members' alignment must match. frepfarm's
# evaluators come compiled from libfrep_core.a (the project's Release flags).
g++ -O2 -march=native -std=c++17 -I "$SRC/libfive/include" -I /usr/include/eigen3 -I "$ROOT/core/include" \
  -I "$HERE" "$HERE/bench_eval_libfive.cpp" "$core" "$lib" -ltbb -lpthread \
  -Wl,-rpath,"$(dirname "$lib")" -o "$work/bench_eval_libfive"
"$work/bench_eval_libfive" "$@"
