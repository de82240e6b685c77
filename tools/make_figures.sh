#!/usr/bin/env bash
# Regenerates every figure in docs/img/ from fresh runs of the simulator (build first:
# cmake --build build). Needs python3-matplotlib.
set -euo pipefail
cd "$(dirname "$0")/.."
bin=build/app/craneassist
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT

# README: flow prescaling on a flow-limited pump.
small=(--pump-max-flow "100 L/min" --prime-mover-power "200 kW")
$bin replay examples/replays/combined_move.csv "${small[@]}" --scaling none --log "$out/cm_none.csv" >/dev/null
$bin replay examples/replays/combined_move.csv "${small[@]}" --scaling flow --log "$out/cm_flow.csv" >/dev/null
tools/plot_direction.py "$out/cm_none.csv" "$out/cm_flow.csv" docs/img/combined_move.png \
  --labels "no scaling" "flow prescaling" --flow-limit 100

# docs/scaling.md: what the operator feels, before (archived logs of commit 9969e41,
# docs/data/feel-before/) and now.
$bin replay examples/replays/suite/push_x_plus.csv --log "$out/push.csv" >/dev/null
$bin replay examples/replays/suite/reversal_slow.csv --log "$out/reversal.csv" >/dev/null
tools/plot_feel.py docs/img/operator_feel.png \
  --run "push straight out" docs/data/feel-before/push_x_plus.csv "$out/push.csv" \
  --run "slow reversal" docs/data/feel-before/reversal_slow.csv "$out/reversal.csv"

# docs/scaling.md: the heavy lift, flow prescaling only against full scaling. The joint-space
# pseudo-inverse, with which this lift is power-bound (the energy-optimal default needs less
# power for it and is bound by the cylinders' speeds first).
hl=(examples/replays/heavy_lift.csv --payload 650 --settle 1.5 --resolution pinv-joint)
$bin replay "${hl[@]}" --scaling flow --log "$out/hl_flow.csv" >/dev/null
$bin replay "${hl[@]}" --scaling full --log "$out/hl_full.csv" >/dev/null
tools/plot_direction.py "$out/hl_flow.csv" "$out/hl_full.csv" docs/img/heavy_lift.png \
  --labels "flow prescaling only" "full scaling (LS power bound)" --power-limit 35

# docs/scaling.md: the 2R experiment of the power-limited scaling paper.
$bin research experiment-2r --power-bound actuator_sum --log "$out/2r_sum.csv" >/dev/null
$bin research experiment-2r --power-bound load_sensing --log "$out/2r_ls.csv" >/dev/null
tools/plot_power.py "$out/2r_sum.csv" "$out/2r_ls.csv" 5000 docs/img/scaling_2r.png
# docs/polytope.md: the flow manipulability polytope at the start pose, with a 120 L/min pump so
# that the flow cuts it, and a stick pushed out and sideways at 0.5 m/s.
$bin research polytope --pump-max-flow "120 L/min" --direction 1,0,0.5 --speed 0.5 \
  --plot docs/img/polytope.png >/dev/null
echo "figures written to docs/img/"
