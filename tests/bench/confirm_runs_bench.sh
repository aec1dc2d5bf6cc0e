#!/usr/bin/env bash
# What the confirm phase (exploration.confirm_runs) buys: replays the agent
# and random search over a family of recorded studies with 20 seeds each,
# at the budget alone and then with up to N confirm runs after it, and
# prints per study and strategy in how many seeds the recording's cheapest
# feasible design was found and confirmed (no cheaper design left untried
# by the seed's runs), and the median confirm runs spent.
#   tests/bench/confirm_runs_bench.sh [budget] [confirm_runs] [family]
#                                     [initial_points]
# Families as in agent_targets_bench.sh (default held-out). ADSE_BIN picks
# the binary. initial_points (default 0) replays the agent with that many
# seeded space-filling points after its first, as agent_targets_bench.sh.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
budget="${1:-15}"
confirm="${2:-5}"
family="${3:-held-out}"
initial="${4:-0}"
build="${ADSE_BUILD:-${root}/build}"
adse="${ADSE_BIN:-${build}/bin/adse}"
# shellcheck source=tests/bench/lib/studies.sh
source "${root}/tests/bench/lib/studies.sh"
for value in "${budget}" "${confirm}"; do
  if ! [[ "${value}" =~ ^[1-9][0-9]*$ ]]; then
    echo "confirm_runs_bench.sh: '${value}' is not a positive whole number" \
      "(budget, confirm runs)" >&2
    exit 2
  fi
done
require_initial_points "${initial}"
require_adse "${adse}"
out="$(mktemp -d)"
trap 'rm -rf "${out}"' EXIT
select_studies "${family}" "${out}" "${root}" "${build}" || exit 2

echo "studies: ${family}; budget ${budget}, up to ${confirm} confirm runs," \
  "seeds 1..20, the agent's initial points ${initial}; $(basename "${adse}")"
machine_line
echo
echo "| study | strategy | found at the budget | confirmed at the budget | found with confirm runs | confirmed with confirm runs | confirm runs spent (median / max) |"
echo "|---|---|---|---|---|---|---|"
for dir in "${studies[@]}"; do
  for runs in 0 "${confirm}"; do
    "${adse}" explore --replay "${dir}" --strategy agent,random \
      --budget "${budget}" --confirm-runs "${runs}" \
      --initial-points "${initial}" --seeds 20 --json \
      >"${out}/${runs}.json"
  done
  /usr/bin/python3 - "${out}/0.json" "${out}/${confirm}.json" \
    "$(basename "${dir}")" <<'PY'
import json, statistics, sys
before, after = (json.load(open(p)) for p in sys.argv[1:3])
for name in ("agent", "random"):
    b, a = before["strategies"][name], after["strategies"][name]
    spent = [run["confirm_evaluations"] for run in a["runs"]]
    print(f"| `{sys.argv[3]}` | {name} "
          f"| {b['seeds_that_found_cheapest_feasible']} of 20 "
          f"| {b['seeds_that_confirmed_cheapest']} of 20 "
          f"| {a['seeds_that_found_cheapest_feasible']} of 20 "
          f"| {a['seeds_that_confirmed_cheapest']} of 20 "
          f"| {statistics.median(spent):g} / {max(spent)} |")
PY
done
