#!/bin/sh
# Sanitizer runs of the tests (CI: deploy/test.sh; issue 34). Two builds of only the targets
# needed, each in its own directory: ASan+UBSan of core_tests, lang_tests, cli_unit_tests,
# cli_tests and farm_tests (with the frep and frep-worker processes they start; any error fails
# the run, leaks too) and TSan of farm_tests (the multithreaded master, the worker's I/O and
# compute threads). A report is a failure: the script exits 1 with the report's first lines.
# Usage: run_sanitizers.sh [asan|tsan|all] (default all).
# FREP_ASAN_BUILD / FREP_TSAN_BUILD name the build directories (default build-asan, build-tsan).
# Each run's filter leaves out the few tests that take minutes under the sanitizer (named below,
# with their time); they run in the Release ctest.
set -eu
HERE=$(cd "$(dirname "$0")" && pwd)
REPO=$(cd "$HERE/../.." && pwd)
WHICH=${1:-all}
JOBS=$(nproc)

# Release code (what users run) with line tables, frame pointers and the sanitizer. No test
# discovery at build time (PRE_TEST): it would run the sanitized binaries inside the build.
build() {
  dir=$1 flags=$2
  cmake -S "$REPO" -B "$dir" -DCMAKE_BUILD_TYPE=Release -DFREP_BUILD_BENCH=OFF \
      -DCMAKE_GTEST_DISCOVER_TESTS_DISCOVERY_MODE=PRE_TEST \
      -DCMAKE_CXX_FLAGS="$flags -g1 -fno-omit-frame-pointer" \
      -DCMAKE_EXE_LINKER_FLAGS="$flags" -DCMAKE_SHARED_LINKER_FLAGS="$flags" >/dev/null
  # shellcheck disable=SC2086
  cmake --build "$dir" -j"$JOBS" --target $TARGETS >"$dir/build.log" 2>&1 || {
    tail -40 "$dir/build.log"
    echo "run_sanitizers: build of $dir failed"
    exit 1
  }
}

# binary, filter, log: the gtest binary under the sanitizer; a failed test or a report of any
# process it started fails. Reports go to files (log_path, set by the caller to $REPORTS/<tool>,
# one file per process): the frep and frep-worker processes the CLI and farm tests start are
# sanitized too, and their reports would otherwise be lost (a worker that dies is replaced and
# the job succeeds; a test of frep reads its stderr and exit code, not a report).
run() {
  bin=$1 filter=$2 log=$3
  start=$(date +%s)
  rm -rf "$REPORTS" && mkdir -p "$REPORTS"
  status=0
  "$bin" --gtest_filter="$filter" >"$log" 2>&1 || status=$?
  what="$(basename "$bin") under $(basename "$(dirname "$(dirname "$bin")")")"
  # A report printed to stderr instead (UBSan's, in the test process or in a frep-worker whose
  # stderr is the test's: a worker that dies of it is replaced and its job passes) fails too.
  if grep -aqE "runtime error:|ERROR: AddressSanitizer|ERROR: LeakSanitizer|WARNING: ThreadSanitizer" "$log"; then
    grep -aE -A12 "runtime error:|ERROR: AddressSanitizer|ERROR: LeakSanitizer|WARNING: ThreadSanitizer" "$log" | head -60
    echo "run_sanitizers: $what: a sanitizer report in the test log ($log)"
    exit 1
  fi
  if [ -n "$(ls "$REPORTS")" ]; then
    for r in "$REPORTS"/*; do
      echo "--- $r"
      head -60 "$r"
    done
    echo "run_sanitizers: $what: sanitizer reports from $(ls "$REPORTS" | wc -l) processes (in $REPORTS; test log: $log)"
    exit 1
  fi
  if [ "$status" != 0 ]; then
    grep -aE "^\[  FAILED  \]" "$log" | sort -u | head -20 || true
    tail -40 "$log"
    echo "run_sanitizers: $what FAILED, exit $status (log: $log)"
    exit 1
  fi
  skipped=$(grep -ac '^\[  SKIPPED \] .* ms)$' "$log" || true)
  echo "run_sanitizers: $what: $(grep -ac '^\[       OK \]' "$log") passed, $skipped skipped, $(( $(date +%s) - start )) s"
  if [ "$skipped" != 0 ]; then grep -a '^\[  SKIPPED \] .* ms)$' "$log" | sed 's/^/run_sanitizers:   /'; fi
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
# A farm test that forks its master and skips itself in a process with other threads: it runs
# alone, in a process of its own, after the others.
ALONE_FARM=Faults.StoppedMasterDoesNotCountItsWorkersDead
ASAN_CORE_FILTER=${ASAN_CORE_FILTER-"-$SLOW_CORE"}
ASAN_FARM_FILTER=${ASAN_FARM_FILTER-"-$ALONE_FARM"}
# The language test that takes minutes under ASan+UBSan: MorphologyClosedForm.ClosingOfTwoBalls...
# (47 s in Release; not done after 279 s under ASan+UBSan at load 7.5, 2026-12-06). The other
# 275 language tests took 328 s there, the slowest LangFuzz.MutatedSeeds 87 s.
SLOW_LANG=MorphologyClosedForm.ClosingOfTwoBallsFillsTheNeck
ASAN_LANG_FILTER=${ASAN_LANG_FILTER-"-$SLOW_LANG"}
ASAN_CLI_UNIT_FILTER=${ASAN_CLI_UNIT_FILTER-"*"}
# The CLI tests that take the longest in Release (ctest's cost data): Hardening.DamagedVdb... 57 s,
# VolumeSplineCli.TenThousandPoint... 41 s, FrepTest.UncertifiedSearches... 22 s: minutes under
# ASan+UBSan, not run there for lack of time (the slowest of the others under ASan+UBSan at load
# 1 to 3, MeshFarmCli.SameBytesForAnyWorkerCount..., took 38 s). Their code paths (the .vdb
# reader, the farm's mesh, the searches) run in the other tests.
SLOW_CLI=Hardening.DamagedVdbIsRefusedNotMeshed:VolumeSplineCli.TenThousandPointScanMeshesOnTwoWorkers
SLOW_CLI=$SLOW_CLI:FrepTest.UncertifiedSearchesWarnAndStrictFails
ASAN_CLI_FILTER=${ASAN_CLI_FILTER-"-$SLOW_CLI"}
# TSan: the whole farm (the master's thread and merge thread, the workers' I/O and compute
# threads, CURVE's authenticator) and the core's interrupter tests (a cancel from another
# thread). Under TSan, TBB runs each loop on its calling thread (core/src/interrupt/
# interrupter.cpp: Debian's libtbb is not instrumented, so its hand-offs are invisible to TSan),
# so the core's other tests, single-threaded there, are ASan's.
# An empty filter (e.g. TSAN_CORE_FILTER= ) leaves that binary out of that build altogether (CI).
TSAN_CORE_FILTER=${TSAN_CORE_FILTER-"Interrupt.*"}
TSAN_FARM_FILTER=${TSAN_FARM_FILTER-"-$ALONE_FARM"}
# The farm tests' heartbeats, liveness windows, timeouts and test pauses are multiplied by
# FREP_TEST_TIME_SCALE (tests/farm/farm_test_util.h): a sanitized process is several times slower
# (TSan 5 to 15), and on a loaded machine a 100 ms heartbeat then misses its 0.5 s window.
ASAN_TIME_SCALE=${ASAN_TIME_SCALE-2}
TSAN_TIME_SCALE=${TSAN_TIME_SCALE-4}

# tool, build flags: one build and its runs; a binary whose filter is empty is neither built
# nor run (frep and frep-worker are built as the CLI and farm tests' dependencies).
sanitize() {
  tool=$1 flags=$2
  TARGETS=
  if [ -n "$CORE_FILTER" ]; then TARGETS=core_tests; fi
  if [ -n "$LANG_FILTER" ]; then TARGETS="$TARGETS lang_tests"; fi
  if [ -n "$CLI_UNIT_FILTER" ]; then TARGETS="$TARGETS cli_unit_tests"; fi
  if [ -n "$CLI_FILTER" ]; then TARGETS="$TARGETS cli_tests"; fi
  if [ -n "$FARM_FILTER" ]; then TARGETS="$TARGETS farm_tests"; fi
  start=$(date +%s)
  build "$dir" "$flags"
  echo "run_sanitizers: $tool build: $(( $(date +%s) - start )) s"
  REPORTS=$dir/reports
  if [ -n "$CORE_FILTER" ]; then run "$dir/bin/core_tests" "$CORE_FILTER" "$dir/core_tests.log"; fi
  if [ -n "$LANG_FILTER" ]; then run "$dir/bin/lang_tests" "$LANG_FILTER" "$dir/lang_tests.log"; fi
  if [ -n "$CLI_UNIT_FILTER" ]; then run "$dir/bin/cli_unit_tests" "$CLI_UNIT_FILTER" "$dir/cli_unit_tests.log"; fi
  if [ -n "$CLI_FILTER" ]; then run "$dir/bin/cli_tests" "$CLI_FILTER" "$dir/cli_tests.log"; fi
  if [ -n "$FARM_FILTER" ]; then
    run "$dir/bin/farm_tests" "$FARM_FILTER" "$dir/farm_tests.log"
    run "$dir/bin/farm_tests" "$ALONE_FARM" "$dir/farm_tests_alone.log"
  fi
}

if [ "$WHICH" = asan ] || [ "$WHICH" = all ]; then
  dir=${FREP_ASAN_BUILD:-$REPO/build-asan}
  export ASAN_OPTIONS="detect_leaks=1:check_initialization_order=1:strict_init_order=1:log_path=$dir/reports/asan"
  export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1:log_path=$dir/reports/ubsan"
  export LSAN_OPTIONS="suppressions=$HERE/lsan.supp:print_suppressions=0"
  export FREP_TEST_TIME_SCALE=$ASAN_TIME_SCALE
  CORE_FILTER=$ASAN_CORE_FILTER FARM_FILTER=$ASAN_FARM_FILTER LANG_FILTER=$ASAN_LANG_FILTER
  CLI_UNIT_FILTER=$ASAN_CLI_UNIT_FILTER CLI_FILTER=$ASAN_CLI_FILTER
  sanitize asan+ubsan "-fsanitize=address,undefined -fno-sanitize-recover=undefined"
  unset ASAN_OPTIONS UBSAN_OPTIONS LSAN_OPTIONS FREP_TEST_TIME_SCALE
fi
if [ "$WHICH" = tsan ] || [ "$WHICH" = all ]; then
  dir=${FREP_TSAN_BUILD:-$REPO/build-tsan}
  export TSAN_OPTIONS="halt_on_error=1 second_deadlock_stack=1 suppressions=$HERE/tsan.supp log_path=$dir/reports/tsan"
  export FREP_TEST_TIME_SCALE=$TSAN_TIME_SCALE
  CORE_FILTER=$TSAN_CORE_FILTER FARM_FILTER=$TSAN_FARM_FILTER LANG_FILTER= CLI_UNIT_FILTER= CLI_FILTER=
  sanitize tsan "-fsanitize=thread"
  unset TSAN_OPTIONS FREP_TEST_TIME_SCALE
fi
