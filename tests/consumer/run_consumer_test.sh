#!/usr/bin/env bash
# Installs the build tree into a temporary prefix (cmake --install), then builds tests/consumer
# against it twice, with find_package(frepfarm) and with pkg-config, and runs both programs: the
# model's value at (0.5, 0.25, 0) must be 1 - 0.25 - 0.0625 = 0.6875 exactly. Also runs the
# installed frep and frep-worker.
#   run_consumer_test.sh BUILD_DIR
set -euo pipefail
build="$(cd "$1" && pwd)"
here="$(cd "$(dirname "$0")" && pwd)"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
prefix="$tmp/prefix"

cmake --install "$build" --prefix "$prefix" >"$tmp/install.log"
for f in bin/frep bin/frep-worker include/frep/lang/hyperfun.h include/frep/io/vdb_writer.h \
         include/frep/evaluators/eval.h; do
  [ -e "$prefix/$f" ] || { echo "not installed: $f"; exit 1; }
done
"$prefix/bin/frep" --version
"$prefix/bin/frep-worker" --help >/dev/null

expect=0.6875
cmake -S "$here" -B "$tmp/cmake-build" -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_BUILD_TYPE=Release >"$tmp/configure.log" \
  || { cat "$tmp/configure.log"; exit 1; }
cmake --build "$tmp/cmake-build" >"$tmp/build.log" || { cat "$tmp/build.log"; exit 1; }
got="$("$tmp/cmake-build/consumer")"
[ "$got" = "$expect" ] || { echo "find_package consumer printed '$got', expected $expect"; exit 1; }
echo "find_package(frepfarm): $got"

pc="$(find "$prefix" -name frepfarm.pc)"
export PKG_CONFIG_PATH="$(dirname "$pc")"
# shellcheck disable=SC2046
c++ -O1 -o "$tmp/consumer-pc" "$here/main.cpp" $(pkg-config --cflags --libs frepfarm)
got="$("$tmp/consumer-pc")"
[ "$got" = "$expect" ] || { echo "pkg-config consumer printed '$got', expected $expect"; exit 1; }
echo "pkg-config frepfarm: $got"
