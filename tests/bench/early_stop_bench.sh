#!/usr/bin/env bash
# Host cost of an exhaustive campaign with and without early stop: runs the
# scenario's whole space twice (harness.early_stop true, then false; no
# cache) and prints a markdown table of runs, early stops, the sum of the
# workers' wall time (host core-hours: one worker holds one core) and the
# campaign's wall time, and whether both found the same feasible set.
#   tests/bench/early_stop_bench.sh [scenario] [workers]
# For a study too long to run twice: given its exhaustive campaign recorded
# with early stop (campaign.h5), only the runs that recording stopped early
# are run again, every EVERY-th of them (1 by default) in the order of their
# points, each both ways with `adse simulate`, `workers` at a time and the
# two ways of a point side by side, so that both see the same load. Prints
# each pair, and the recording's worker wall time without early stop
# estimated by scaling its stopped runs by the sample's ratio.
#   tests/bench/early_stop_bench.sh scenario workers recording.h5
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
    # Any early_stop of its own dropped first: a key may appear once.
    sed -E -e '/^harness: *\{/s/early_stop: *(true|false) *,? *//' \
      -e "s/^harness: *\{/harness: {early_stop: $2, /" \
      -e '/^harness:/s/, *\}/}/' "$1" >"$3"
  elif grep -q '^harness:' "$1"; then
    echo "early_stop_bench: $1: write its harness section as a flow map {...}" >&2
    exit 2
  else
    { cat "$1"; echo "harness: {early_stop: $2}"; } >"$3"
  fi
}
variant "${scenario}" true "${on}"
variant "${scenario}" false "${off}"

if [ -n "${3:-}" ]; then
  recording="$(realpath "$3")"
  # The recording's stopped points, "name=value,..." one per line.
  /usr/bin/python3 - "${recording}" "${EVERY:-1}" >"${out}/points" <<'EOF'
import sys
import h5py
path, every = sys.argv[1], int(sys.argv[2])
with h5py.File(path, "r") as f:
    e = f["evaluations"]
    names = [n.decode() if isinstance(n, bytes) else n for n in e["point"].attrs["names"]]
    cols = [e["point"][n][:] for n in names]
    reasons = [r.decode() if isinstance(r, bytes) else r for r in e["reason"][:]]
stopped = sorted(tuple(c[i] for c in cols) for i, r in enumerate(reasons)
                 if r.startswith("constraint_violated"))
if not stopped:
    sys.exit("early_stop_bench: %s has no run stopped early" % path)
for p in stopped[::every]:
    print(",".join("%s=%g" % (n, v) for n, v in zip(names, p)))
EOF
  echo "scenario: ${scenario}"
  echo "recording: ${recording} (of the runs it stopped early, one in ${EVERY:-1})"
  echo "machine: $(nproc) cores, $(lscpu | sed -n 's/^Model name: *//p'), load $(cut -d' ' -f1 /proc/loadavg); ${workers} runs at a time"
  while read -r point; do
    printf 'on %s\noff %s\n' "${point}" "${point}"
  done <"${out}/points" >"${out}/jobs"
  export adse on off out
  # xargs fails when a run fails: its wall time would be missing from a sum.
  xargs -P "${workers}" -L 1 bash -c '
    file="${on}"
    [ "$0" = off ] && file="${off}"
    "${adse}" simulate "${file}" --point "$1" --json -q \
      -o "${out}/$0-$1.h5" >"${out}/$0-$1.json"' <"${out}/jobs"
  /usr/bin/python3 - "${recording}" "${out}" <<'EOF'
import json
import sys
import h5py
import numpy as np
recording, out = sys.argv[1], sys.argv[2]
with h5py.File(recording, "r") as f:
    e = f["evaluations"]
    wall = np.asarray(e["wall_s"][:])
    reasons = [r.decode() if isinstance(r, bytes) else r for r in e["reason"][:]]
stopped = np.array([r.startswith("constraint_violated") for r in reasons])
print()
print("| point | early stop on: ended, nav time, wall | off: ended, nav time, wall |")
print("|---|---|---|")
sums = {"on": 0.0, "off": 0.0}
for point in open(out + "/points").read().split():
    cells = []
    for mode in ("on", "off"):
        d = json.load(open("%s/%s-%s.json" % (out, mode, point)))
        sums[mode] += d["timing_s"]["wall"]
        nav = d["metrics"]["nav_time_s"]
        cells.append("%s, %s, %.1f s" % (
            d["termination_reason"], "-" if nav is None else "%.1f s" % nav,
            d["timing_s"]["wall"]))
    print("| %s | %s | %s |" % (point, cells[0], cells[1]))
ratio = sums["off"] / sums["on"]
print("| sum | %.1f s | %.1f s (%.2f times) |" % (sums["on"], sums["off"], ratio))
stopped_s, total_s = wall[stopped].sum(), wall.sum()
estimate_s = total_s - stopped_s + stopped_s * ratio
print()
print("recording: %d runs, %d stopped early, worker wall %.0f s (%.2f core-hours; %.0f s in its stopped runs)" % (
    len(wall), stopped.sum(), total_s, total_s / 3600.0, stopped_s))
print("without early stop, estimated: %.0f s (%.2f core-hours): early stop saves %.0f %%" % (
    estimate_s, estimate_s / 3600.0, 100.0 * (1.0 - total_s / estimate_s)))
EOF
  exit 0
fi

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
