#!/usr/bin/env bash
# Installs the Debian dependencies (idempotent) and builds everything into build/ (Release).
set -euo pipefail
cd "$(dirname "$0")/.."
./deploy/install-deps.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j"$(nproc)"
