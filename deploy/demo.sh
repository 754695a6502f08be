#!/usr/bin/env bash
# README command 1: set up, build, and run the main jobs on an example: the blended chair of the
# F-rep survey sampled at 192^3 and meshed at 160^3 by a farm of local workers (one per core),
# written as an OpenVDB level set and a PLY mesh with their reports, plus a slice picture and a
# shaded render (frep render: the image's tiles computed by the same local workers).
set -euo pipefail
cd "$(dirname "$0")/.."
./deploy/build.sh
mkdir -p out
bounds=-1.5,-1.5,-0.5,1.5,1.5,2.5
./build/bin/frep sample examples/chair.hf -b "$bounds" --res 192 -O out/chair.vdb
./build/bin/frep mesh examples/chair.hf -b "$bounds" --res 160 -O out/chair.ply
./build/bin/frep slice examples/chair.hf --axis y --at 0.8 -b "$bounds" --res 512 -O out/chair-slice.png
./build/bin/frep render examples/chair.hf -b "$bounds" --size 512x512 -O out/chair-render.png
echo "demo: out/chair.vdb, out/chair.ply (with their .report.json), out/chair-slice.png and out/chair-render.png are ready"
