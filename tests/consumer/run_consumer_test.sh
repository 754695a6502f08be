#!/usr/bin/env bash
# Installs the build tree into a temporary prefix (cmake --install), then builds tests/consumer
# against it twice, with find_package(frepfarm) and with pkg-config, and runs both programs: the
# model's value at (0.5, 0.25, 0) must be 1 - 0.25 - 0.0625 = 0.6875 exactly. Also runs the
# installed frep and frep-worker, and the installed Python module.
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
# The man page renders, and the completion completes frep's verbs.
man1="$(find "$prefix" -path '*/man1/frep.1')"
[ -n "$man1" ] || { echo "not installed: man1/frep.1"; exit 1; }
man -l "$man1" 2>/dev/null | grep -q "frep" || { echo "man -l $man1 shows nothing"; exit 1; }
completion="$prefix/share/bash-completion/completions/frep"
[ -e "$completion" ] || { echo "not installed: share/bash-completion/completions/frep"; exit 1; }
verbs="$(bash -c "source '$completion'; COMP_WORDS=(frep me); COMP_CWORD=1; COMP_LINE='frep me'; COMP_POINT=7; \$(complete -p frep | sed -E 's/.*-F ([^ ]+).*/\1/') frep me frep; echo \"\${COMPREPLY[*]}\"")"
case " $verbs " in *" mesh "*) ;; *) echo "the installed completion offers '$verbs' for 'frep me'"; exit 1 ;; esac
echo "man page and completion installed ($verbs)"
"$prefix/bin/frep" --version
"$prefix/bin/frep-worker" --help >/dev/null
# The installed frep finds its modules (LIBDIR/frepfarm): OpenVDB (libfrep_vdb.so) for .vdb work.
printf 'ball(x[3], a[1]) { ball = 1 - x[1]^2 - x[2]^2 - x[3]^2; }\n' >"$tmp/ball.hf"
"$prefix/bin/frep" sample "$tmp/ball.hf" -O "$tmp/ball.vdb" -b 1.5 --res 16 --workers 0 >/dev/null
"$prefix/bin/frep" mesh "$tmp/ball.vdb" -O "$tmp/ball.ply" >/dev/null
[ -s "$tmp/ball.ply" ] || { echo "the installed frep wrote no mesh of its .vdb"; exit 1; }
echo "installed frep: .vdb written and read through $(find "$prefix" -name libfrep_vdb.so | sed "s|$prefix/||")"
# ... and its mesh file module for .3mf and .glb.
"$prefix/bin/frep" mesh "$tmp/ball.hf" -O "$tmp/ball.3mf" -b 1.5 --res 16 >/dev/null
"$prefix/bin/frep" mesh "$tmp/ball.hf" -O "$tmp/ball.glb" -b 1.5 --res 16 >/dev/null
[ -s "$tmp/ball.3mf" ] && [ -s "$tmp/ball.glb" ] || { echo "the installed frep wrote no .3mf or .glb"; exit 1; }
echo "installed frep: .3mf and .glb written through $(find "$prefix" -name libfrep_mesh_files.so | sed "s|$prefix/||")"

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

# The Python package, when it was built: installed under the prefix (site/frepfarm/), importable
# from there.
module="$(find "$prefix" -name 'frepfarm*.so' | head -n 1)"
if ls "$build"/python/frepfarm/frepfarm*.so >/dev/null 2>&1; then
  [ -n "$module" ] || { echo "the Python module was built but not installed"; exit 1; }
  got="$(cd "$tmp" && PYTHONPATH="$(dirname "$(dirname "$module")")" /usr/bin/python3 -c \
    'import frepfarm; print(frepfarm.compile("my_model(x[3], a[1]) { my_model = 1 - x[1]^2 - x[2]^2 - x[3]^2; }").eval([0.5, 0.25, 0.0])[0])')"
  [ "$got" = "$expect" ] || { echo "installed Python module printed '$got', expected $expect"; exit 1; }
  echo "installed Python module ($module): $got"
fi
