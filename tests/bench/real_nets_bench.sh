#!/usr/bin/env bash
# Drives the real and OSM-derived networks Debian's sumo-tools ships: for
# each net, seeded random routes of 500 m to 2 km (SUMO's shortest route
# for passenger cars, checked with sumolib), with seeded traffic flows and
# the net's own traffic lights, each run once with `adse simulate` at a
# generous point. adse routes them itself (round the block where SUMO's
# route turns around tighter than the car can, else a turn in several
# moves) and refuses a goal where not even that fits; those rows say
# "refused". Prints a markdown table: net, route (SUMO's length and
# adse's), reached goal, nav time, dominant stop reason, peak memory
# (/usr/bin/time -v), simulated seconds per wall second, how far `adse
# world --follow-ideal`'s ground-truth controller strays from the ideal
# path outside junctions, with the number of places the path turns
# tighter than the car can (tests/bench/ideal_path_error.py), and the
# route's turns in several moves with the moves of each (at U-turns and
# at corners sharper than the car, "c"; "s" where the lanes left no room
# and the manoeuvre uses the road's shoulders).
#   tests/bench/real_nets_bench.sh [routes-per-net] [net-name ...]
# ROUTES_SEED (default 1) seeds the routes and flows; POINT (default
# cores=16,freq_ghz=2.1) is the design point; KEEP=DIR keeps the scenarios,
# run files and logs in DIR. ONLY="A10KW-2 joined-0" runs only the routes
# named (the others are drawn all the same, so the names stay). IDEAL_ONLY=1 drives only the ground-truth
# controller (no stack, a few seconds a route): the table then has the
# route, whether and when that driver reached the goal, and its error.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
adse="${ADSE_BIN:-${root}/build/bin/adse}"
routes="${1:-3}"
shift || true
point="${POINT:-cores=16,freq_ghz=2.1}"
seed="${ROUTES_SEED:-1}"
tools=/usr/share/sumo/tools
declare -A nets=(
  [DRT]="${tools}/game/DRT/osm.net.xml"
  [A10KW]="${tools}/game/A10KW/osm.net.xml"
  [acosta]="${tools}/sumolib/scenario/scenarios/RealWorld/acosta/acosta_buslanes.net.xml"
  [joined]="${tools}/sumolib/scenario/scenarios/RealWorld/joined/joined_buslanes.net.xml"
  [RiLSA1]="${tools}/sumolib/scenario/scenarios/RealWorld/RiLSA_example1/rilsa1.net.xml"
  [RiLSA2]="${tools}/sumolib/scenario/scenarios/RealWorld/RiLSA_example2/rilsa2.net.xml"
  [RiLSA3]="${tools}/sumolib/scenario/scenarios/RealWorld/RiLSA_example3/rilsa3.net.xml"
  [RiLSA4]="${tools}/sumolib/scenario/scenarios/RealWorld/RiLSA_example4/rilsa4.net.xml"
  [bs3d]="${tools}/game/bs3d/bs.net.xml"
  [grid6]="${tools}/game/grid6/grid6.net.xml"
  [square]="${tools}/game/square/square.net.xml"
  [pasubio]="${tools}/sumolib/scenario/scenarios/RealWorld/pasubio/pasubio_buslanes.net.xml"
)
# kuehne (a 300 m square) has no shortest route of 500 m; corridor,
# highway, ramp and racing are a road or two, hiking footpaths.
names=("$@")
[ ${#names[@]} -eq 0 ] &&
  names=(DRT A10KW pasubio acosta joined RiLSA1 RiLSA2 RiLSA4 bs3d grid6 square)
if [ -n "${KEEP:-}" ]; then
  out="${KEEP}"
  mkdir -p "${out}"
else
  out="$(mktemp -d)"
  trap 'rm -rf "${out}"' EXIT
fi
py=/usr/bin/python3

# Writes ${out}/<net>-<i>.yaml for `routes` routes of net $1 ($2: its file).
make_scenarios() {
  PYTHONPATH="${tools}" "${py}" - "$1" "$2" "${routes}" "${seed}" "${out}" <<'PY'
import random, sys, zlib
import sumolib
name, path, count, seed, out = sys.argv[1], sys.argv[2], int(sys.argv[3]), int(sys.argv[4]), sys.argv[5]
net = sumolib.net.readNet(path)
# Seeded by the bench seed and the net's name, so each net's routes stay
# the same when other nets are added.
rng = random.Random(seed * 1000003 + zlib.crc32(name.encode()))

def car_lane(edge):
    for lane in edge.getLanes():
        if lane.allows("passenger"):
            return lane
    return None

edges = sorted((e for e in net.getEdges()
                if e.getFunction() == "" and car_lane(e) is not None
                and car_lane(e).getLength() >= 30.0),
               key=lambda e: e.getID())

def route(lo, hi):
    for _ in range(2000):
        a, b = rng.choice(edges), rng.choice(edges)
        if a == b:
            continue
        path, _ = net.getShortestPath(a, b, vClass="passenger")
        if not path:
            continue
        length = sum(e.getLength() for e in path[1:-1]) + \
            a.getLength() - 10.0 + b.getLength() / 2
        if lo <= length <= hi:
            return a, b, length
    raise SystemExit("%s: no route of %g..%g m found" % (name, lo, hi))

for i in range(count):
    a, b, length = route(500.0, 2000.0)
    flows = []
    for _ in range(3):
        fa, fb, _ = route(200.0, 3000.0)
        flows.append('{from: "%s", to: "%s", vehicles_per_hour: 300}' % (fa.getID(), fb.getID()))
    la, lb = car_lane(a), car_lane(b)
    with open("%s/%s-%d.yaml" % (out, name, i), "w") as f:
        f.write("""# real_nets_bench: %s route %d (%.0f m by SUMO's shortest route)
adse: 1
name: %s-%d
world:
  map: {net: %s}
  traffic: {seed: %d, flows: [%s]}
task:
  start: {edge: "%s", pos_m: 10, lane: %d}
  goal: {edge: "%s", pos_m: %.1f, lane: %d}
  speed_limit_kmh: 40
  timeout_s: 900
design_space:
  cores:    {bind: platform.cores,    range: [1, 16]}
  freq_ghz: {bind: platform.freq_ghz, values: [1.2, 2.1]}
output: %s/results
""" % (name, i, length, name, i, path, seed + i, ", ".join(flows),
       a.getID(), la.getIndex(), b.getID(), b.getLength() / 2, lb.getIndex(), out))
    print("%s-%d %.0f" % (name, i, length))
PY
}

echo "point: ${point}; routes per net: ${routes}; seed: ${seed}"
echo "machine: $(nproc) cores, $(lscpu | sed -n 's/^Model name: *//p'), load $(cut -d' ' -f1 /proc/loadavg)"
echo
ideal_only="${IDEAL_ONLY:-0}"
if [ "${ideal_only}" = 1 ]; then
  echo "| net | route | length m, SUMO's shortest / adse's | ideal driver reached goal | its time s | ideal driver off path m, outside junctions / all | turns tighter than the car's | manoeuvres (moves; c: at a corner, s: onto the shoulders) |"
  echo "|---|---|---|---|---|---|---|---|"
else
  echo "| net | route | length m, SUMO's shortest / adse's | reached goal | ended | nav time s | dominant stop reason | stood s | collisions (caused by the ego) | peak RSS MB | sim s / wall s | ideal driver off path m, outside junctions / all | turns tighter than the car's | manoeuvres (moves; c: at a corner, s: onto the shoulders) |"
  echo "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
fi
reached=0
total=0
refused=0
within=0  # routes the ideal driver keeps within 1 m outside junctions
ideal_total=0
for name in "${names[@]}"; do
  net="${nets[${name}]:-}"
  if [ -z "${net}" ] || [ ! -f "${net}" ]; then
    echo "real_nets_bench: unknown net or file missing: ${name}" >&2
    exit 2
  fi
  while read -r run length; do
    if [ -n "${ONLY:-}" ] && [[ " ${ONLY} " != *" ${run} "* ]]; then
      continue
    fi
    yaml="${out}/${run}.yaml"
    # adse's own route first: it goes round the block where SUMO's turns
    # around tighter than the car can, turns in several moves where no
    # such way leads on, and refuses a goal where not even that fits.
    if ! "${adse}" world "${yaml}" --no-scan --json -o "${out}/${run}-route" \
        >"${out}/${run}-route.json" 2>"${out}/${run}-route.log"; then
      echo "| ${name} | ${run} | ${length} / - | refused | $(tail -n1 "${out}/${run}-route.log") | | | | | | | | | |"
      refused=$((refused + 1))
      continue
    fi
    length="${length} / $("${py}" -c 'import json,sys; print("%.0f" % json.load(open(sys.argv[1]))["ideal_path_length_m"])' "${out}/${run}-route.json")"
    turnarounds="$("${py}" -c 'import json,sys; t = json.load(open(sys.argv[1]))["turnarounds"]; print("%d%s" % (len(t), " (%s)" % ", ".join(("c " if x["kind"] == "corner" else "") + ("s " if x["on_shoulders"] else "") + str(x["moves"]) for x in t) if t else ""))' "${out}/${run}-route.json")"
    if [ "${ideal_only}" != 1 ] &&
      ! /usr/bin/time -v -o "${out}/${run}.time" "${adse}" simulate "${yaml}" \
        --point "${point}" --json -q -o "${out}/${run}.h5" \
        >"${out}/${run}.json" 2>"${out}/${run}.log"; then
      echo "| ${name} | ${run} | ${length} | error | $(tail -n1 "${out}/${run}.log") | | | | | | | | | |"
      total=$((total + 1))
      continue
    fi
    ideal="n/a | n/a"
    # Exit code 1: the goal was not reached; its trajectory still counts.
    "${adse}" world "${yaml}" --follow-ideal --no-scan \
      -o "${out}/${run}-ideal" >"${out}/${run}-ideal.log" 2>&1 || true
    if [ -f "${out}/${run}-ideal/trajectory.csv" ]; then
      read -r off all turns < <(PYTHONPATH="${tools}" "${py}" \
        "${root}/tests/bench/ideal_path_error.py" "${net}" "${out}/${run}-ideal")
      ideal="${off} / ${all} | ${turns}"
      ideal_total=$((ideal_total + 1))
      if "${py}" -c 'import sys; sys.exit(float(sys.argv[1]) > 1.0)' "${off}"; then
        within=$((within + 1))
      fi
    fi
    if [ "${ideal_only}" = 1 ]; then
      summary="${out}/${run}-ideal/summary.json"
      if [ -f "${summary}" ]; then
        drove="$("${py}" -c 'import json,sys; d = json.load(open(sys.argv[1])); print("%s | %.1f" % ("yes" if d["reached_goal"] else "no", d["time_s"]))' "${summary}")"
      else
        drove="error: $(tail -n1 "${out}/${run}-ideal.log") | "
      fi
      echo "| ${name} | ${run} | ${length} | ${drove} | ${ideal} | ${turnarounds} |"
      total=$((total + 1))
      case "${drove}" in yes*) reached=$((reached + 1)) ;; esac
      continue
    fi
    line="$("${py}" - "${out}/${run}.json" "${out}/${run}.time" "${name}" "${run}" "${length}" <<'PY'
import json, re, sys
d = json.load(open(sys.argv[1]))
rss = re.search(r"Maximum resident set size \(kbytes\): (\d+)", open(sys.argv[2]).read())
m, t, s = d["metrics"], d["timing_s"], d["standing"]
if s["by_reason"]:
    top = s["by_reason"][0]
    why = "%s %.1f s" % (top["reason"], top["standing_s"])
    if top["reason"] == "obstacle":
        why += " (track %d%s, %.1f m)" % (top["track_id"],
            ", static structure" if top["static_structure"] else "", top["obstacle_gap_m"])
else:
    why = "-"
ended = d["termination_reason"]
if d.get("termination_detail"):
    ended += " (%s)" % d["termination_detail"]
print("| %s | %s | %s | %s | %s | %.1f | %s | %.1f | %d (%d) | %.0f | %.2f |" % (
    sys.argv[3], sys.argv[4], sys.argv[5], "yes" if m["completed"] else "no",
    ended, m["nav_time_s"], why, s["standing_s"], m["collisions"],
    m["ego_collisions"],
    int(rss.group(1)) / 1024 if rss else float("nan"), t["simulated"] / t["wall"]))
PY
)"
    echo "${line} ${ideal} | ${turnarounds} |"
    total=$((total + 1))
    case "${line}" in *"| yes |"*) reached=$((reached + 1)) ;; esac
  done < <(make_scenarios "${name}" "${net}")
done
echo
echo "reached the goal: ${reached} of ${total}; refused (only a U-turn reaches the goal, and no turn in several moves fits there): ${refused}"
echo "ideal driver within 1 m of the ideal path outside junctions: ${within} of ${ideal_total}"
