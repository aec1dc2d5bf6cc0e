#!/usr/bin/env bash
# Two builds of adse on the same runs: each run is simulated by build A and
# by build B one after the other (A first on odd runs, B first on even ones,
# so that neither always meets the host's slower minutes), the metrics
# compared (with the counted cost model they must be equal; the measured
# one charges the host's CPU time, which a faster build changes) and the wall
# times printed side by side, with their ratio over all runs.
#   tests/bench/two_builds_bench.sh A B [scenario:point ...]
# A and B are adse binaries; a run is a scenario and a design point
# (name=value,...). Without runs, a default set over the bundled
# scenarios. Exit 1 when a counted run's metrics differ between the builds.
set -euo pipefail
if [ $# -lt 2 ]; then
  echo "usage: $0 adse-A adse-B [scenario:point ...]" >&2
  exit 2
fi
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
a="$(realpath "$1")"
b="$(realpath "$2")"
shift 2
runs=("$@")
if [ ${#runs[@]} -eq 0 ]; then
  runs=(
    "scenarios/robotaxi_small.yaml:cores=4,freq_ghz=2.1,lidar_hz=14"
    "scenarios/robotaxi_small.yaml:cores=1,freq_ghz=1,lidar_hz=7"
    "scenarios/robotaxi_parking_lot.yaml:cores=6,freq_ghz=2.1,lidar_hz=7"
    "scenarios/valet_parking.yaml:cores=4,freq_ghz=1.5"
    "scenarios/rilsa_traffic_light.yaml:cores=8,freq_ghz=2.1,detector_latency_s=0.1"
    "scenarios/grid_town.yaml:cores=4,freq_ghz=1.8,beams=16"
    "scenarios/osm_drt.yaml:cores=8,freq_ghz=2.1"
  )
fi
out="$(mktemp -d)"
trap 'rm -rf "${out}"' EXIT
cd "${root}"

echo "A: ${a}"
echo "B: ${b}"
echo "machine: $(nproc) cores, $(lscpu | sed -n 's/^Model name: *//p'), load $(cut -d' ' -f1 /proc/loadavg)"
echo
echo "| scenario | point | ended | nav time s | A wall s | B wall s | B / A | metrics |"
echo "|---|---|---|---|---|---|---|---|"
n=0
for run in "${runs[@]}"; do
  scenario="${run%%:*}"
  point="${run#*:}"
  args=("${scenario}" --json -q --point "${point}")
  # A scenario with cases runs its first; its cost model says whether the
  # builds must agree (counted) or may not (measured: the host's CPU time).
  read -r cost_model case_name < <(/usr/bin/python3 - "${scenario}" <<'EOF'
import sys
import yaml
spec = yaml.safe_load(open(sys.argv[1]))
cases = (spec.get("task") or {}).get("cases") or []
print((spec.get("platform") or {}).get("cost_model", "measured"),
      cases[0]["name"] if cases else "")
EOF
)
  [ -n "${case_name}" ] && args+=(--case "${case_name}")
  order=(a b)
  [ $((n % 2)) -eq 1 ] && order=(b a)
  for which in "${order[@]}"; do
    bin="${a}"
    [ "${which}" = b ] && bin="${b}"
    "${bin}" simulate "${args[@]}" -o "${out}/${n}-${which}.h5" >"${out}/${n}-${which}.json"
  done
  /usr/bin/python3 - "${out}/${n}-a.json" "${out}/${n}-b.json" "${scenario}" "${point}" "${cost_model}" <<'EOF' || echo different >>"${out}/differs"
import json
import sys
a, b = (json.load(open(p)) for p in sys.argv[1:3])
same = a["metrics"] == b["metrics"] and a["termination_reason"] == b["termination_reason"]
counted = sys.argv[5] == "counted"
nav = a["metrics"]["nav_time_s"]
wa, wb = a["timing_s"]["wall"], b["timing_s"]["wall"]
print("| %s | %s | %s | %s | %.1f | %.1f | %.2f | %s |" % (
    sys.argv[3], sys.argv[4], a["termination_reason"],
    "-" if nav is None else "%.2f" % nav, wa, wb, wb / wa, "same" if same else "DIFFERENT" if counted else "differ (measured costs)"))
with open(sys.argv[1] + ".walls", "w") as f:
    f.write("%r %r\n" % (wa, wb))
sys.exit(0 if same or not counted else 1)
EOF
  n=$((n + 1))
done
cat "${out}"/*.walls | awk '{ta += $1; tb += $2} END {printf "\nall runs: A %.1f s, B %.1f s, B / A %.2f\n", ta, tb, tb / ta}'
if [ -e "${out}/differs" ]; then
  echo "metrics differ between the builds" >&2
  exit 1
fi
