#!/usr/bin/env bash
# README command 2: set up, build and run every test.
set -euo pipefail
cd "$(dirname "$0")/.."
./deploy/build.sh
# CI runs with ../shared next to the checkout: tests that read its corpus fail, not skip, without it.
export FREP_REQUIRE_CORPUS=1
cd build && ctest --output-on-failure -j"$(nproc)"
cd .. && ./tests/fuzz/run_fuzz.sh build-fuzz  # bounded ASan+UBSan fuzz run of 4 targets (tests/fuzz, docs/cli.md "Fuzzing")
# ASan+UBSan of the core and farm tests (with the frep-worker processes they start), then TSan
# of the farm tests, each in a build of its own; the farm tests' times are stretched for the
# sanitizers' slowness (docs/cli.md "Sanitizers": what runs, what is left out and why, the
# measured times). The language and CLI tests' ASan runs (green, 13 more minutes) and TSan's
# core run (Interrupt.*) are run by hand: CI's 90 minutes hold the core and farm steps only.
ASAN_LANG_FILTER= ASAN_CLI_FILTER= ASAN_CLI_UNIT_FILTER= TSAN_CORE_FILTER= ./tests/sanitize/run_sanitizers.sh all
