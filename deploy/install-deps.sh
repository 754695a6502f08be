#!/usr/bin/env bash
# Installs every Debian 12 package frepfarm needs to build, test and benchmark. Idempotent:
# packages already present are skipped, so a second run does no network access at all.
#   install-deps.sh [--build-only]    --build-only: not the tools only tests use (the Docker
#                                     image's build stage: no Slurm, docker-compose, pytest)
set -euo pipefail
packages=(
  build-essential cmake pkg-config
  libopenvdb-dev libopenvdb-tools python3-openvdb libboost-iostreams-dev
  cppzmq-dev libzmq3-dev
  libprotobuf-dev protobuf-compiler
  libspdlog-dev libtbb-dev libcli11-dev nlohmann-json3-dev libeigen3-dev
  libboost-dev  # header-only: boost::container::small_vector (core/src/meshing/simplifier.h)
  libgtest-dev libgmock-dev libbenchmark-dev libpng-dev
  povray  # frep pov scenes are rendered in tests (docs/pov.md)
  lib3mf-dev libtinygltf-dev  # the .3mf and .glb mesh writers (io/)
  assimp-utils python3-stl  # independent readers of the mesh files in tests/cli/frep_mesh_formats_test.cpp
  clang libclang-rt-14-dev
  pybind11-dev python3-dev python3-numpy python3-venv  # the Python package (python/; venv: pip install .)
  libcpp-httplib-dev  # frep view's HTTP server (cli/view_command.cpp)
)
test_packages=(
  python3-pytest  # tests/python
  clang-format  # ctest clang_format (tests/format/check_format.py): clang-format 14 on Debian 12
  python3-yaml python3-jsonschema docker-compose  # tests/deploy: Compose v1 (docker-compose 1.29) and schemas
  slurm-wlm munge  # tests/deploy/slurm_e2e.sh: a real single-node Slurm (about 16 s to install)
  chromium python3-websocket python3-pil  # tests/view: frep view's page in headless Chromium
)
[ "${1:-}" = --build-only ] || packages+=("${test_packages[@]}")
# npm installs three.js for frep view's page (deploy/build.sh; not the Docker image's build, which
# builds the programs only): Debian's npm, unless node's own packages (e.g. NodeSource's nodejs,
# which conflicts with it) already provide the command.
[ "${1:-}" = --build-only ] || command -v npm >/dev/null || packages+=(npm)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages present"
  exit 0
fi
echo "install-deps: installing ${missing[*]}"
SUDO=""
[ "$(id -u)" -ne 0 ] && SUDO=sudo
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
