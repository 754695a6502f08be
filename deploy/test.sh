#!/usr/bin/env bash
# README command 2: set up, build and run every test.
set -euo pipefail
cd "$(dirname "$0")/.."
./deploy/build.sh
cd build && ctest --output-on-failure -j"$(nproc)"
cd .. && ./tests/fuzz/run_fuzz.sh build-fuzz  # bounded ASan+UBSan fuzz run (tests/fuzz), about 40 s
