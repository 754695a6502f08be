#!/usr/bin/env bash
# Installs every Debian 12 package frepfarm needs to build, test and benchmark. Idempotent:
# packages already present are skipped, so a second run does no network access at all.
set -euo pipefail
packages=(
  build-essential cmake pkg-config
  libopenvdb-dev libopenvdb-tools python3-openvdb libboost-iostreams-dev
  cppzmq-dev libzmq3-dev
  libprotobuf-dev protobuf-compiler
  libspdlog-dev libtbb-dev libcli11-dev nlohmann-json3-dev libeigen3-dev
  libgtest-dev libgmock-dev libbenchmark-dev libpng-dev
  povray  # frep pov scenes are rendered in tests (docs/pov.md)
  clang libclang-rt-14-dev
)
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
