#!/bin/sh
# docs/img/foxglove_layout.png: a recording (the demo replay on a pump held to 6 kW and 35 L/min,
# so power and flow reach their limits) read back with @mcap/core and drawn with the shipped
# layout's paths. Needs a build (build/app/craneassist and the web page's npm packages).
set -eu
root="$(cd "$(dirname "$0")/../.." && pwd)"
build="${BUILD:-$root/build}"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
"$build/app/craneassist" replay --prime-mover-power "6 kW" --pump-max-flow "35 L/min" \
  --mcap "$work/run.mcap" --log "$work/run.csv" | grep -E "mcap:|active limit"
node "$root/tools/foxglove/mcap_to_csv.mjs" "$build/app/web/page/node_modules" "$work/run.mcap" \
  "$work/layout.csv"
/usr/bin/python3 "$root/tools/foxglove/plot_layout.py" "$work/layout.csv" \
  "$root/docs/img/foxglove_layout.png" \
  "craneassist replay --prime-mover-power '6 kW' --pump-max-flow '35 L/min' --mcap run.mcap"
