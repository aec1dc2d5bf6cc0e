#!/usr/bin/env bash
# Installs what is missing, builds adse and runs the most complete job that
# exists on the bundled robotaxi scenario: validate it (280-point space),
# drive its world with a perfect controller while the LiDAR scans, then
# evaluate its start point in closed loop with the AD stack on the virtual
# platform. No network and no LLM needed.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
scripts/build.sh --target adse
scenario=scenarios/robotaxi_parking_lot.yaml
echo "== adse validate $scenario"
build/bin/adse validate --quiet "$scenario"
echo "== adse world $scenario --follow-ideal"
build/bin/adse world "$scenario" --follow-ideal
echo "== adse simulate $scenario (exploration.start_from)"
build/bin/adse simulate "$scenario"
echo "== adse analyze results/robotaxi-parking-lot/simulate (offline re-analysis)"
build/bin/adse analyze results/robotaxi-parking-lot/simulate
