#!/usr/bin/env bash
# frep render of the chair at 1024^2 on the farm (2 worker processes, the image's tiles as
# bricks) against the mesh pipeline for the same view:
# frep mesh (sampling + meshing, in-process on 2 threads, --tolerance 0: no simplification) at a
# voxel about one pixel, then POV-Ray of that mesh at 1024^2 (docs/tools/render_ply.py, if
# povray is installed). Prints wall times and the ratio, measured in this run.
#   bench/bench_render.sh [build-dir] [size]
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
size=${2:-1024}
frep=$build/bin/frep
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
bounds=-1.5,-1.5,-0.5,1.5,1.5,2.5
now() { date +%s.%N; }

t0=$(now)
"$frep" render examples/chair.hf -b "$bounds" --size "${size}x${size}" --workers 2 -O "$tmp/render.png"
t1=$(now)
# The view spans about the box's 3 units over $size pixels: a voxel of one pixel is --res $size.
"$frep" mesh examples/chair.hf -b "$bounds" --res "$size" --workers 0 --threads 2 --tolerance 0 --no-progress -O "$tmp/chair.ply"
t2=$(now)
pov=0
if command -v povray >/dev/null; then
  python3 docs/tools/render_ply.py "$tmp/chair.ply" "$tmp/pov.png" --width "$size" >/dev/null 2>&1 || echo "POV-Ray failed"
  pov=$(echo "$(now) - $t2" | bc)
fi
render=$(echo "$t1 - $t0" | bc)
mesh=$(echo "$t2 - $t1" | bc)
pipeline=$(echo "$mesh + $pov" | bc)
printf 'render %dx%d (2 workers):          %8.2f s\n' "$size" "$size" "$render"
printf 'mesh --res %d (2 threads):          %8.2f s\n' "$size" "$mesh"
printf 'POV-Ray of the mesh at %d^2:        %8.2f s\n' "$size" "$pov"
printf 'pipeline / render:                   %8.2f x\n' "$(echo "$pipeline / $render" | bc -l)"
