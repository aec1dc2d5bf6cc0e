#!/usr/bin/env bash
# Builds every benchmark (target adse_benchmarks) in build/ and runs each
# build/bin/*_bench, after printing what machine the figures come from.
#   scripts/bench.sh [extra google-benchmark flags, e.g. --benchmark_filter=Lidar]
# ADSE_BUILD_DIR overrides the build folder, ADSE_JOBS the build jobs (2) and
# ADSE_BUILD_TYPE the build type of a fresh configure (RelWithDebInfo).
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${ADSE_BUILD_DIR:-${root}/build}"
jobs="${ADSE_JOBS:-2}"

if [[ ! -f "${build}/CMakeCache.txt" ]]; then
  cmake -S "${root}" -B "${build}" \
    -DCMAKE_BUILD_TYPE="${ADSE_BUILD_TYPE:-RelWithDebInfo}"
fi
cmake --build "${build}" --target adse_benchmarks -j "${jobs}"

echo "== machine"
echo "nproc: $(nproc)"
lscpu | grep 'Model name' || true
echo "build type: $(grep -E '^CMAKE_BUILD_TYPE:' "${build}/CMakeCache.txt" | cut -d= -f2)"
echo "load average: $(cut -d' ' -f1-3 /proc/loadavg)"

shopt -s nullglob
benches=("${build}"/bin/*_bench)
if [[ ${#benches[@]} -eq 0 ]]; then
  echo "no benchmarks found in ${build}/bin" >&2
  exit 1
fi
status=0
for bench in "${benches[@]}"; do
  echo
  echo "== $(basename "${bench}")"
  "${bench}" --benchmark_format=console "$@" || status=1
done
# Closed-loop runs of the robotaxi example: outcome and wall-time split per
# design point (a few minutes; ADSE_BENCH_SWEEP=0 skips it).
if [[ "${ADSE_BENCH_SWEEP:-1}" != 0 ]]; then
  cmake --build "${build}" --target adse -j "${jobs}"
  echo
  echo "== simulate_sweep"
  ADSE_BIN="${build}/bin/adse" "${root}/tests/bench/simulate_sweep.sh" || status=1
  echo
  echo "== campaign_bench"
  ADSE_BIN="${build}/bin/adse" "${root}/tests/bench/campaign_bench.sh" || status=1
fi
exit "${status}"
