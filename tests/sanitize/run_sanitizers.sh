#!/bin/sh
# Sanitizer runs of the core and farm tests (CI: deploy/test.sh; issue 34). Two builds of only
# the targets needed, core_tests and farm_tests (with the frep-worker they start), each in its
# own directory: ASan+UBSan (any error fails the run, leaks too) and TSan (the multithreaded
# master, the worker's compute thread, TBB loops). A report is a failure: the script exits 1
# with the log's tail. Usage: run_sanitizers.sh [asan|tsan|all] (default all).
# FREP_ASAN_BUILD / FREP_TSAN_BUILD name the build directories (default build-asan, build-tsan).
# Each run's filter leaves out the few tests that take minutes under the sanitizer (named below,
# with their time); they run in the Release ctest.
set -eu
HERE=$(cd "$(dirname "$0")" && pwd)
REPO=$(cd "$HERE/../.." && pwd)
WHICH=${1:-all}
JOBS=$(nproc)

# Release code (what users run) with line tables, frame pointers and the sanitizer.
build() {
  dir=$1 flags=$2
  cmake -S "$REPO" -B "$dir" -DCMAKE_BUILD_TYPE=Release -DFREP_BUILD_BENCH=OFF \
      -DCMAKE_CXX_FLAGS="$flags -g1 -fno-omit-frame-pointer" \
      -DCMAKE_EXE_LINKER_FLAGS="$flags" -DCMAKE_SHARED_LINKER_FLAGS="$flags" >/dev/null
  cmake --build "$dir" -j"$JOBS" --target core_tests farm_tests >"$dir/build.log" 2>&1 || {
    tail -40 "$dir/build.log"
    echo "run_sanitizers: build of $dir failed"
    exit 1
  }
}

# binary, filter, log: the gtest binary under the sanitizer; a report or a failed test fails.
run() {
  bin=$1 filter=$2 log=$3
  start=$(date +%s)
  "$bin" --gtest_filter="$filter" >"$log" 2>&1 || {
    grep -m1 -A30 -E "^(==[0-9]+==ERROR|WARNING: ThreadSanitizer|SUMMARY: )|runtime error:" "$log" || tail -40 "$log"
    echo "run_sanitizers: $(basename "$bin") FAILED under $(basename "$(dirname "$(dirname "$bin")")") (log: $log)"
    exit 1
  }
  echo "run_sanitizers: $(basename "$(dirname "$(dirname "$bin")")") $(basename "$bin"): $(grep -c '^\[       OK \]' "$log") passed, $(( $(date +%s) - start )) s"
}

# The core tests that take minutes even in Release (measured by ctest's cost data, seconds of
# wall time at load ~15): Measure.Cylinder 309, MinkowskiAlgebra.RandomSums... 145,
# Measure.SameNumbersForAnyThreadCount 54, Measure.Torus 40, MinkowskiDiscSum.Volumes... 20,
# VolumeSpline.SphereFrom2000... 19, Measure.TighterTolerance... 15, MinkowskiBidisc.Random... 15:
# 617 of the 742 s of all 344 core tests. Their code runs in the other tests too.
SLOW_CORE=Measure.Cylinder:MinkowskiAlgebra.RandomSumsAgreeInSignWithTheCertifiedSearch
SLOW_CORE=$SLOW_CORE:Measure.SameNumbersForAnyThreadCount:Measure.Torus
SLOW_CORE=$SLOW_CORE:MinkowskiDiscSum.VolumesMatchTheMixedVolumeFormulas
SLOW_CORE=$SLOW_CORE:VolumeSpline.SphereFrom2000SurfacePointsWithinHalfAVoxel
SLOW_CORE=$SLOW_CORE:Measure.TighterToleranceTightensAndStillHolds
SLOW_CORE=$SLOW_CORE:MinkowskiBidisc.RandomTwoAxisSumsAgreeInSignWithTheCertifiedSearch
ASAN_CORE_FILTER=${ASAN_CORE_FILTER:-"-$SLOW_CORE"}
ASAN_FARM_FILTER=${ASAN_FARM_FILTER:-"*"}
# TSan: the core's threaded algorithms (TBB loops: sample, mesh, simplify, render, measure, the
# interrupter carried onto TBB's threads) and the whole farm (the master's threads, workers).
TSAN_CORE_FILTER=${TSAN_CORE_FILTER:-"Sample.*:Mesh.*:MeshSimplify.*:Render.*:Plane.*:Interrupt.*:Measure.OffCentreBall:BandDistance.*-$SLOW_CORE"}
TSAN_FARM_FILTER=${TSAN_FARM_FILTER:-"*"}

if [ "$WHICH" = asan ] || [ "$WHICH" = all ]; then
  dir=${FREP_ASAN_BUILD:-$REPO/build-asan}
  start=$(date +%s)
  build "$dir" "-fsanitize=address,undefined -fno-sanitize-recover=undefined"
  echo "run_sanitizers: asan+ubsan build: $(( $(date +%s) - start )) s"
  export ASAN_OPTIONS=detect_leaks=1:check_initialization_order=1:strict_init_order=1
  export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
  run "$dir/bin/core_tests" "$ASAN_CORE_FILTER" "$dir/core_tests.log"
  run "$dir/bin/farm_tests" "$ASAN_FARM_FILTER" "$dir/farm_tests.log"
  unset ASAN_OPTIONS UBSAN_OPTIONS
fi
if [ "$WHICH" = tsan ] || [ "$WHICH" = all ]; then
  dir=${FREP_TSAN_BUILD:-$REPO/build-tsan}
  start=$(date +%s)
  build "$dir" "-fsanitize=thread"
  echo "run_sanitizers: tsan build: $(( $(date +%s) - start )) s"
  export TSAN_OPTIONS="halt_on_error=1 second_deadlock_stack=1 suppressions=$HERE/tsan.supp"
  run "$dir/bin/core_tests" "$TSAN_CORE_FILTER" "$dir/core_tests.log"
  run "$dir/bin/farm_tests" "$TSAN_FARM_FILTER" "$dir/farm_tests.log"
  unset TSAN_OPTIONS
fi
