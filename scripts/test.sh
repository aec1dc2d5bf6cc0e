#!/usr/bin/env bash
# Installs what is missing, builds, and runs the whole test suite with ctest.
# Extra arguments go to ctest, e.g. scripts/test.sh -L world
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
scripts/format.sh --check
scripts/build.sh
cd build
ctest --output-on-failure -j"${ADSE_JOBS:-2}" "$@"
