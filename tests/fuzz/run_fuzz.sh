#!/bin/sh
# Bounded fuzz run (CI, deploy/test.sh): builds tests/fuzz with clang (ASan+UBSan, libFuzzer) in
# BUILD, writes seeds from the current formats (fuzz_seeds) and runs each target for a fixed
# number of iterations from its seeds and its kept corpus (corpus/<target>/: examples of each
# finding, replayed by the normal build's fuzz_corpus_tests). Allocations over 512 MiB and runs
# over 30 s count as findings. Exit 0: no findings; otherwise the failing input is kept as
# BUILD/findings/<target>-crash-* (add it to corpus/<target>/ with its fix).
# FUZZ_SCALE=N multiplies every iteration count (a longer local run).
# Then the process fuzz loops (tests/cli/process_fuzz: the frep binary run once per damaged
# input, about a minute), built in the Release build RELEASE (FREP_BUILD, default build/), and
# the Python module's fuzz run (fuzz_python.py, at most a minute) against that build's module.
set -eu
HERE=$(cd "$(dirname "$0")" && pwd)
REPO=$(cd "$HERE/../.." && pwd)
BUILD=${1:-$REPO/build-fuzz}
RELEASE=${FREP_BUILD:-$REPO/build}
if [ ! -f "$RELEASE/CMakeCache.txt" ]; then
  echo "run_fuzz: no Release build at $RELEASE for the process fuzz loops (deploy/build.sh makes it; FREP_BUILD=DIR names another)"
  exit 2
fi
SCALE=${FUZZ_SCALE:-1}
cmake -S "$HERE" -B "$BUILD" -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE=Debug >/dev/null
cmake --build "$BUILD" -j"$(nproc)"
seeds=$(mktemp -d)
trap 'rm -rf "$seeds"' EXIT
"$BUILD/fuzz_seeds" "$seeds"
mkdir -p "$BUILD/findings"
# target, iterations, extra options, seed directories
run() {
  target=$1 runs=$(($2 * SCALE)) opts=$3
  shift 3
  work=$(mktemp -d)
  start=$(date +%s)
  # shellcheck disable=SC2086
  "$BUILD/fuzz_$target" -runs="$runs" -seed=1 $opts -timeout=30 -rss_limit_mb=2048 -malloc_limit_mb=512 \
      -print_final_stats=0 -artifact_prefix="$BUILD/findings/$target-" "$work" "$HERE/corpus/$target" "$@" \
      >"$BUILD/findings/$target.log" 2>&1 || {
    tail -40 "$BUILD/findings/$target.log"
    echo "run_fuzz: $target: FINDING (input kept in $BUILD/findings/)"
    rm -rf "$work"
    exit 1
  }
  echo "run_fuzz: $target: $runs runs, $(( $(date +%s) - start )) s, 0 findings ($(ls "$work" | wc -l) new inputs)"
  rm -rf "$work"
}
run hf 4000 "-max_len=4096" "$REPO/examples"
run payload 30000 "" "$seeds/payload"
run journal 20000 "" "$seeds/journal"
# The mesh readers (the first byte picks .stl/.obj/.ply) and frep pov's scene preprocessor: small
# hand-made seeds in corpus/mesh and corpus/pov, and the POV scenes of examples/roerdink.
run mesh 100000 "-max_len=2048"
run pov 40000 "-max_len=4096" "$REPO/examples/roerdink"
# OpenVDB's readers leak the node they were building when a refused size throws (their bug, a
# few hundred KiB in a process that then exits 3): leaks are not findings for this target.
export ASAN_OPTIONS=detect_leaks=0
run vdb 8000 "-detect_leaks=0" "$seeds/vdb"
unset ASAN_OPTIONS
# The process fuzz loops (GoogleTest; frep itself is the Release binary, as users run it).
start=$(date +%s)
cmake --build "$RELEASE" -j"$(nproc)" --target cli_process_fuzz >/dev/null
"$RELEASE/bin/cli_process_fuzz" >"$BUILD/findings/process.log" 2>&1 || {
  tail -40 "$BUILD/findings/process.log"
  echo "run_fuzz: process fuzz loops: FAILED (log: $BUILD/findings/process.log)"
  exit 1
}
echo "run_fuzz: process fuzz loops: $(grep -c '^\[       OK \]' "$BUILD/findings/process.log") passed, $(( $(date +%s) - start )) s"
# The Python module (python/frepfarm_module.cpp) as Python calls it: fuzz_python.py feeds mutated
# models and odd arguments from seed 1 to the Release build's module in a child process; a signal,
# a hang, MemoryError or an "internal error" is a finding (kept as findings/python-<case>.txt).
if [ -f "$RELEASE/python/CMakeFiles/frepfarm_python.dir/flags.make" ]; then
  cmake --build "$RELEASE" -j"$(nproc)" --target frepfarm_python >/dev/null
  /usr/bin/python3 "$HERE/fuzz_python.py" --module-dir "$RELEASE/python" --cases $((3000 * SCALE)) \
      --budget $((60 * SCALE)) --findings "$BUILD/findings" || {
    echo "run_fuzz: python: FINDING (replay: tests/fuzz/fuzz_python.py --seed 1 --replay CASE)"
    exit 1
  }
else
  echo "run_fuzz: python: the frepfarm module is not configured in $RELEASE (no pybind11); skipped"
fi
