#!/bin/sh
# Bounded fuzz run (CI): builds tests/fuzz with clang (ASan+UBSan, libFuzzer) in BUILD and runs
# every target for a fixed number of iterations from its kept corpus. Exit 0: no findings.
set -eu
HERE=$(cd "$(dirname "$0")" && pwd)
BUILD=${1:-$HERE/../../build-fuzz}
RUNS=${FUZZ_RUNS:-20000}
cmake -S "$HERE" -B "$BUILD" -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE=Debug >/dev/null
cmake --build "$BUILD" -j2
for target in journal; do
  work=$(mktemp -d)
  cp "$HERE"/corpus/$target/* "$work"/ 2>/dev/null || true
  "$BUILD/fuzz_$target" -runs="$RUNS" -seed=1 -max_len=4096 -rss_limit_mb=1024 -malloc_limit_mb=512 \
      -artifact_prefix="$work/crash-" "$work"
  rm -rf "$work"
done
