# shellcheck shell=bash
# The families of recorded studies the replay benches run over, sourced by
# them. select_studies FAMILY SCRATCH ROOT BUILD sets `studies` (folders)
# for FAMILY (held-out, committed, recordings or all) of the checkout at
# ROOT; held-out landscapes are written under SCRATCH with
# BUILD/bin/make_landscapes. Returns 2 with a message (named by the
# sourcing script) for an unknown family or a missing make_landscapes.
#   held-out    the landscapes no strategy was tuned on
#               (make_landscapes --held-out: other loads, grids, costs,
#               bounds and noise than tests/data/landscapes);
#   committed   the landscapes of tests/data/landscapes;
#   recordings  the real recorded campaigns of tests/data (every folder
#               with a campaign.h5 outside landscapes/);
#   all         committed, then recordings.
select_studies() {
  local family="$1" scratch="$2" root="$3" build="$4" dir index
  studies=()
  case "${family}" in
    held-out | committed | recordings | all) ;;
    *)
      echo "${0##*/}: unknown family '${family}'" \
        "(expected held-out, committed, recordings or all)" >&2
      return 2
      ;;
  esac
  if [[ "${family}" == held-out ]]; then
    if [[ ! -x "${build}/bin/make_landscapes" ]]; then
      echo "${0##*/}: no make_landscapes at ${build}/bin/make_landscapes" \
        "(build first, or set ADSE_BUILD)" >&2
      return 2
    fi
    "${build}/bin/make_landscapes" --held-out "${scratch}/landscapes" \
      >/dev/null
    for dir in "${scratch}"/landscapes/*/; do studies+=("${dir%/}"); done
  fi
  if [[ "${family}" == committed || "${family}" == all ]]; then
    for dir in "${root}"/tests/data/landscapes/*/; do
      studies+=("${dir%/}")
    done
  fi
  if [[ "${family}" == recordings || "${family}" == all ]]; then
    for index in "${root}"/tests/data/*/campaign.h5; do
      studies+=("$(dirname "${index}")")
    done
  fi
}

# Exits 2 with a message when there is no adse binary at $1.
require_adse() {
  if [[ ! -x "$1" ]]; then
    echo "${0##*/}: no adse binary at $1 (build first, or set ADSE_BIN)" >&2
    exit 2
  fi
}

# Exits 2 with a message when $1, the agent's initial points
# (exploration.initial_points, --initial-points), is not a whole number.
require_initial_points() {
  if ! [[ "$1" =~ ^(0|[1-9][0-9]*)$ ]]; then
    echo "${0##*/}: initial_points '$1' is not a whole number" >&2
    exit 2
  fi
}

# "machine: 2 cores, <model>, load 0.87", for the bench's header.
machine_line() {
  echo "machine: $(nproc) cores, $(lscpu | sed -n 's/^Model name: *//p')," \
    "load $(cut -d' ' -f1 /proc/loadavg)"
}
