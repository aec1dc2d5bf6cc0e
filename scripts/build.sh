#!/usr/bin/env bash
# Configures and builds adse into build/ (binary: build/bin/adse).
# Usage: scripts/build.sh [cmake --build args, e.g. --target adse]
set -euo pipefail
cd "$(dirname "$0")/.."
jobs="${ADSE_JOBS:-2}"
if [ ! -f build/CMakeCache.txt ]; then
  cmake -S . -B build -DCMAKE_BUILD_TYPE="${ADSE_BUILD_TYPE:-RelWithDebInfo}"
fi
cmake --build build -j"$jobs" "$@"
