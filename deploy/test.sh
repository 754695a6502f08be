#!/usr/bin/env bash
# README command 2: set up, build and run every test.
set -euo pipefail
cd "$(dirname "$0")/.."
./deploy/build.sh
# CI runs with ../shared next to the checkout: tests that read its corpus fail, not skip, without it.
export FREP_REQUIRE_CORPUS=1
cd build && ctest --output-on-failure -j"$(nproc)"
cd .. && ./tests/fuzz/run_fuzz.sh build-fuzz  # bounded ASan+UBSan fuzz run of 4 targets (tests/fuzz, docs/cli.md "Fuzzing")
# ASan+UBSan of the core tests in a build of its own (docs/cli.md "Sanitizers": the TSan run of
# the farm tests is run by hand until its timing-bound tests are shown steady on a free machine).
ASAN_FARM_FILTER= ./tests/sanitize/run_sanitizers.sh asan
