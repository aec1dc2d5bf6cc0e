#!/usr/bin/env bash
# Sweeps design points of a scenario with `adse simulate --json` and prints
# a markdown table: outcome, nav time, control rate, latency, drops, and
# where the wall time went. Also repeats one point to show the spread of
# the measured cost model.
#   tests/bench/simulate_sweep.sh [scenario] [repeat-point]
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
adse="${ADSE_BIN:-${root}/build/bin/adse}"
scenario="${1:-${root}/scenarios/robotaxi_parking_lot.yaml}"
repeat_point="${2:-cores=12,freq_ghz=1.5,lidar_hz=14}"
out="$(mktemp -d)"
trap 'rm -rf "${out}"' EXIT
py=/usr/bin/python3

row() {
  "${adse}" simulate "${scenario}" --point "$1" --json -q -o "${out}/run.h5" 2>/dev/null |
    "${py}" -c '
import json, sys
d = json.load(sys.stdin); m = d["metrics"]; t = d["timing_s"]
p = ", ".join("%s=%g" % kv for kv in d["point"].items())
n = lambda v: float("nan") if v is None else v
print("| %s | %s | %.1f | %.2f | %.3f | %d | %.2f | %.1f | %.1f | %.1f | %.2f | %.2f | %.2f | %.2f | %.1f |" % (
    p, d["termination_reason"], m["nav_time_s"], m["ctrl_rate_hz"], n(m["e2e_latency_p50_s"]),
    m["lidar_frames_dropped"], m["cpu_utilization"], t["wall"], t["stack_and_executor"], n(t["stack_cpu"]),
    n(t["executor"]), t["world"], t["lidar"], t["hdf5_write"], t["simulated"] / t["wall"]))'
}

echo "scenario: ${scenario}"
echo "machine: $(nproc) cores, $(lscpu | sed -n 's/^Model name: *//p'), load $(cut -d' ' -f1 /proc/loadavg)"
echo
echo "| point | ended | nav_time_s | ctrl_rate_hz | e2e p50 s | LiDAR drops | CPU util | wall s | stack+exec s | stack s | executor s | world s | LiDAR s | HDF5 s | sim s / wall s |"
echo "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
for point in ${SWEEP_POINTS:-cores=28,freq_ghz=2.1,lidar_hz=14 cores=1,freq_ghz=1.0,lidar_hz=14 \
    cores=4,freq_ghz=1.2,lidar_hz=14 cores=6,freq_ghz=1.5,lidar_hz=7 cores=18,freq_ghz=1.8,lidar_hz=7 \
    cores=23,freq_ghz=1.5,lidar_hz=7}; do
  row "${point}"
done
echo
echo "cores sweep at 1.5 GHz, 14 Hz:"
echo
echo "| point | ended | nav_time_s | ctrl_rate_hz | e2e p50 s | LiDAR drops | CPU util | wall s | stack+exec s | stack s | executor s | world s | LiDAR s | HDF5 s | sim s / wall s |"
echo "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
for cores in ${SWEEP_CORES:-1 2 4 6 8 12 16 20 28}; do
  row "cores=${cores},freq_ghz=1.5,lidar_hz=14"
done
echo
echo "measured-model spread, ${REPEATS:-5} runs of ${repeat_point}:"
echo
echo "| point | ended | nav_time_s | ctrl_rate_hz | e2e p50 s | LiDAR drops | CPU util | wall s | stack+exec s | stack s | executor s | world s | LiDAR s | HDF5 s | sim s / wall s |"
echo "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
for _ in $(seq "${REPEATS:-5}"); do row "${repeat_point}"; done
