#!/usr/bin/env bash
# Harness benchmarks (figures in the README's performance section):
#  1. per-run overhead of `adse run` over `adse simulate` of the same point:
#     a one-point campaign (spec load, pool and cgroups, worker process,
#     reading and analysing the run, writing every view) against the bare
#     simulate command, median of REPEATS each, interleaved;
#  2. 1 vs 2 workers on the same batch of runs (the small scenario's
#     4- and 16-core points, no cache), wall time of the whole campaign.
#   tests/bench/campaign_bench.sh
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
adse="${ADSE_BIN:-${root}/build/bin/adse}"
repeats="${REPEATS:-5}"
work="$(mktemp -d)"
# The scenario variants sit beside the original so that its relative paths
# (the cost profile) resolve.
one_point_yaml="${root}/scenarios/.campaign_bench_one.$$.yaml"
batch_yaml="${root}/scenarios/.campaign_bench_batch.$$.yaml"
trap 'rm -rf "${work}" "${one_point_yaml}" "${batch_yaml}"' EXIT

echo "machine: $(nproc) cores, $(lscpu | sed -n 's/^Model name: *//p'), load $(cut -d' ' -f1 /proc/loadavg)"

sed -e 's/values: \[1, 4, 16\]/values: [4]/' -e 's/values: \[1.0, 2.1\]/values: [2.1]/' \
    -e 's/values: \[7, 14\]/values: [14]/' \
    "${root}/scenarios/robotaxi_small.yaml" > "${one_point_yaml}"
sed -e 's/values: \[1, 4, 16\]/values: [4, 16]/' \
    "${root}/scenarios/robotaxi_small.yaml" > "${batch_yaml}"

now() { date +%s.%N; }
median() { sort -g | awk '{a[NR]=$1} END {print (NR%2) ? a[(NR+1)/2] : (a[NR/2]+a[NR/2+1])/2}'; }

# Per-run overhead: the same 8 points simulated one by one with `adse
# simulate` (which also analyses and writes the run file) against one
# campaign of them on 1 worker; the difference per run is what the harness
# adds (worker process, reading and analysing the run again, pictures,
# index, report). Interleaved REPEATS times; medians.
points=$(for c in 4 16; do for f in 1 2.1; do for l in 7 14; do echo "cores=$c,freq_ghz=$f,lidar_hz=$l"; done; done; done)
n_points=$(echo "${points}" | wc -l)
sim_totals=(); run_totals=(); one_point=()
for i in $(seq "${repeats}"); do
  t0=$(now)
  for p in ${points}; do
    "${adse}" simulate "${batch_yaml}" --point "${p}" -o "${work}/sim.h5" -q > /dev/null
  done
  t1=$(now)
  rm -rf "${work}/camp"
  "${adse}" run "${batch_yaml}" -o "${work}/camp" --strategy exhaustive --workers 1 \
    --no-cache --quiet > /dev/null
  t2=$(now)
  rm -rf "${work}/one"
  "${adse}" run "${one_point_yaml}" -o "${work}/one" --strategy exhaustive --workers 1 \
    --no-cache --quiet > /dev/null
  t3=$(now)
  "${adse}" simulate "${one_point_yaml}" --point cores=4,freq_ghz=2.1,lidar_hz=14 \
    -o "${work}/sim.h5" -q > /dev/null
  t4=$(now)
  sim_totals+=("$(echo "${t1} - ${t0}" | bc)")
  run_totals+=("$(echo "${t2} - ${t1}" | bc)")
  one_point+=("$(echo "(${t3} - ${t2}) - (${t4} - ${t3})" | bc)")
done
sim_median=$(printf '%s\n' "${sim_totals[@]}" | median)
run_median=$(printf '%s\n' "${run_totals[@]}" | median)
one_median=$(printf '%s\n' "${one_point[@]}" | median)
echo
echo "| what | median wall s (${repeats} repeats) |"
echo "|---|---|"
echo "| ${n_points} x adse simulate, robotaxi_small points with 4 and 16 cores | ${sim_median} |"
echo "| adse run of the same ${n_points} points, 1 worker | ${run_median} |"
echo "| harness overhead per run | $(echo "scale=1; (${run_median} - ${sim_median}) * 1000 / ${n_points}" | bc) ms |"
echo "| fixed cost of a campaign (one-point campaign minus one simulate) | $(echo "scale=1; ${one_median} * 1000" | bc) ms |"

echo
echo "| workers | wall s for ${n_points} runs | speed-up |"
echo "|---|---|---|"
one=""
for workers in 1 2; do
  rm -rf "${work}/batch-${workers}"
  t0=$(now)
  "${adse}" run "${batch_yaml}" -o "${work}/batch-${workers}" --strategy exhaustive \
    --workers "${workers}" --no-cache --quiet > /dev/null
  t1=$(now)
  wall=$(echo "${t1} - ${t0}" | bc)
  [ -z "${one}" ] && one="${wall}"
  echo "| ${workers} | ${wall} | $(echo "scale=2; ${one} / ${wall}" | bc) |"
done
