#!/usr/bin/env bash
# Host cost of an exhaustive campaign with and without early stop: runs the
# scenario's whole space twice (harness.early_stop true, then false; no
# cache) and prints a markdown table of runs, early stops, the sum of the
# workers' wall time (host core-hours: one worker holds one core) and the
# campaign's wall time, and whether both found the same feasible set.
#   tests/bench/early_stop_bench.sh [scenario] [workers]
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
scenario="$(realpath "${1:-${root}/scenarios/robotaxi_small.yaml}")"
workers="${2:-2}"
out="$(mktemp -d)"
# A copy of the binary: the campaigns run for long, and a rebuild meanwhile
# must not swap the workers' program under them.
cp "${ADSE_BIN:-${root}/build/bin/adse}" "${out}/adse"
adse="${out}/adse"
# The variants sit beside the scenario so that its relative paths resolve.
dir="$(dirname "${scenario}")"
on="${dir}/.early_stop_on.$$.yaml"
off="${dir}/.early_stop_off.$$.yaml"
trap 'rm -rf "${out}" "${on}" "${off}"' EXIT

# harness.early_stop set to $2 in a copy of the scenario ($1 -> $3).
variant() {
  if grep -q '^harness: *{' "$1"; then
    sed "s/^harness: *{/harness: {early_stop: $2, /" "$1" >"$3"
  elif grep -q '^harness:' "$1"; then
    echo "early_stop_bench: $1: write its harness section as a flow map {...}" >&2
    exit 2
  else
    { cat "$1"; echo "harness: {early_stop: $2}"; } >"$3"
  fi
}
variant "${scenario}" true "${on}"
variant "${scenario}" false "${off}"

echo "scenario: ${scenario}"
echo "machine: $(nproc) cores, $(lscpu | sed -n 's/^Model name: *//p'), load $(cut -d' ' -f1 /proc/loadavg); ${workers} workers"
echo
echo "| early_stop | runs | stopped early | feasible | worker wall s (sum) | host core-hours | campaign wall s |"
echo "|---|---|---|---|---|---|---|"
for mode in on off; do
  file="${on}"
  [ "${mode}" = off ] && file="${off}"
  start=$(date +%s.%N)
  "${adse}" run "${file}" -o "${out}/${mode}" --strategy exhaustive \
    --budget 1000000 --workers "${workers}" --no-cache -q >/dev/null
  end=$(date +%s.%N)
  /usr/bin/python3 - "${out}/${mode}/campaign.h5" "${mode}" "${start}" "${end}" <<'EOF'
import sys
import h5py
import numpy as np
path, mode, start, end = sys.argv[1], sys.argv[2], float(sys.argv[3]), float(sys.argv[4])
with h5py.File(path, "r") as f:
    e = f["evaluations"]
    wall = np.asarray(e["wall_s"][:])
    feasible = np.asarray(e["feasible"][:])
    reasons = [r.decode() if isinstance(r, bytes) else r for r in e["reason"][:]]
stopped = sum(r.startswith("constraint_violated") for r in reasons)
print("| %s | %d | %d | %d | %.0f | %.3f | %.0f |" % (
    "true" if mode == "on" else "false", len(wall), stopped, int(feasible.sum()),
    wall.sum(), wall.sum() / 3600.0, end - start))
EOF
done
# Early stop may only end runs that are infeasible anyway.
/usr/bin/python3 - "${out}/on/campaign.h5" "${out}/off/campaign.h5" <<'EOF'
import sys
import h5py
def feasible_points(path):
    with h5py.File(path, "r") as f:
        e = f["evaluations"]
        names = [n.decode() if isinstance(n, bytes) else n for n in e["point"].attrs["names"]]
        cols = [e["point"][n][:] for n in names]
        return {tuple(c[i] for c in cols) for i in range(len(cols[0])) if e["feasible"][i]}
a, b = feasible_points(sys.argv[1]), feasible_points(sys.argv[2])
print()
print("same feasible set with and without early stop: %s" % ("yes" if a == b else "NO (%d vs %d)" % (len(a), len(b))))
sys.exit(0 if a == b else 1)
EOF
