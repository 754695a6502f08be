#!/usr/bin/env bash
# Installs the Debian dependencies (idempotent) and builds everything into build/ (Release).
set -euo pipefail
cd "$(dirname "$0")/.."
./deploy/install-deps.sh
# frep view's page uses three.js from npm (view/web/package-lock.json), installed here into
# view/web/node_modules and served by frep itself: viewing needs no network.
if [ ! -f view/web/node_modules/.package-lock.json ] || [ view/web/package-lock.json -nt view/web/node_modules/.package-lock.json ]; then
  (cd view/web && npm ci --no-audit --no-fund)
fi
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j"$(nproc)"
