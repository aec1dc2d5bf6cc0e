#!/usr/bin/env bash
# The built-in agent against issue 16's targets on landscapes it was not
# tuned on: writes the held-out family (make_landscapes --held-out: other
# loads, grids, costs, bounds and noise than tests/data/landscapes) to a
# temporary folder, replays the agent and random search over each with 20
# seeds, and prints a markdown table of what the targets ask (the cheapest
# feasible design found in how many seeds, the median true Pareto points,
# the median hypervolume ratio, random search's median beside it).
#   tests/bench/agent_held_out_bench.sh [budget] [committed]
# With `committed` as the second argument, the committed landscapes of
# tests/data/landscapes are replayed the same way instead.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
budget="${1:-15}"
family="${2:-held-out}"
build="${ADSE_BUILD:-${root}/build}"
adse="${ADSE_BIN:-${build}/bin/adse}"
out="$(mktemp -d)"
trap 'rm -rf "${out}"' EXIT

if [[ "${family}" == committed ]]; then
  dir="${root}/tests/data/landscapes"
else
  dir="${out}/landscapes"
  "${build}/bin/make_landscapes" --held-out "${dir}" >/dev/null
fi
names="$(cd "${dir}" && ls -d */ | tr -d /)"

echo "landscapes: ${family}; budget ${budget}, seeds 1..20; $(basename "${adse}")"
echo "machine: $(nproc) cores, $(lscpu | sed -n 's/^Model name: *//p'), load $(cut -d' ' -f1 /proc/loadavg)"
echo
echo "| landscape | points | front | agent: cheapest found (seeds) | agent: true Pareto (median) | agent: hypervolume ratio (median) | random: hypervolume ratio (median) | wall s |"
echo "|---|---|---|---|---|---|---|---|"
for name in ${names}; do
  start=$(date +%s.%N)
  "${adse}" explore --replay "${dir}/${name}" --strategy agent,random \
    --budget "${budget}" --seeds 20 --json >"${out}/${name}.json"
  end=$(date +%s.%N)
  /usr/bin/python3 - "${out}/${name}.json" "${name}" "${start}" "${end}" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
a = d["strategies"]["agent"]
r = d["strategies"]["random"]
print(f"| `{sys.argv[2]}` | {d.get('recorded_evaluations', '')} | {a['true_front_size']} "
      f"| {a['seeds_that_found_cheapest_feasible']} of 20 "
      f"| {a['true_pareto_found']['median']:g} "
      f"| {a['hypervolume_ratio']['median']:.3f} "
      f"| {r['hypervolume_ratio']['median']:.3f} "
      f"| {float(sys.argv[4]) - float(sys.argv[3]):.0f} |")
PY
done
