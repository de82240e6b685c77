#!/usr/bin/env bash
# The robustness matrix of docs/valves.md#the-machine-it-meets: the operator-feel suite on every
# machine variant of examples/machines/variants.yaml, first with the controller's own valve model
# (uncalibrated), then after `calibrate`'s sweep on each machine (--calibrated); writes both CSVs
# and the Markdown table into OUT (default build/robustness) and prints the table.
#   tools/valves/robustness_matrix.sh [OUT] [craneassist suite options, e.g. --only push_x]
set -euo pipefail
cd "$(dirname "$0")/../.."
out="${1:-build/robustness}"
shift || true
bin="${CRANEASSIST:-build/app/craneassist}"
mkdir -p "$out"
for mode in uncalibrated calibrated; do
  extra=()
  [ "$mode" = calibrated ] && extra=(--calibrated)
  # The suite exits 1 when a run misses a target: that is a figure here, not a failure.
  "$bin" suite examples/replays/suite.yaml --variants examples/machines/variants.yaml \
    --matrix "$out/$mode.csv" "${extra[@]}" "$@" >"$out/$mode.txt" || [ $? -eq 1 ]
done
python3 tools/valves/matrix_table.py "$out/uncalibrated.csv" "$out/calibrated.csv" | tee "$out/matrix.md"
