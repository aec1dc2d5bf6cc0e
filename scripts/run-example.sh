#!/usr/bin/env bash
# Installs what is missing, builds adse and runs its main job on the bundled
# robotaxi scenario: validate it (280-point space), check its world with a
# perfect controller, then `adse run` — the campaign with the default
# built-in `agent` strategy (budget 15, worker processes in cgroups where
# possible), ending with the Pareto front, report.md, pareto.png and
# campaign.h5 in results/robotaxi-parking-lot/. Finally re-analyses the
# campaign's run files offline. No network and no LLM needed. Running it
# again resumes (nothing is simulated twice).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
scripts/build.sh --target adse
scenario=scenarios/robotaxi_parking_lot.yaml
echo "== adse validate $scenario"
build/bin/adse validate --quiet "$scenario"
echo "== adse world $scenario --follow-ideal"
build/bin/adse world "$scenario" --follow-ideal
echo "== adse run $scenario"
build/bin/adse run "$scenario"
echo "== adse analyze results/robotaxi-parking-lot (offline re-analysis)"
build/bin/adse analyze results/robotaxi-parking-lot | tail -n 2
