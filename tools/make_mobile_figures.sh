#!/usr/bin/env bash
# Regenerates docs/img/mobile_follow.png and the figures of docs/mobile.md: the crane on wheels
# on the example tool path in the paper's two cases, with one pump for the drive and the crane
# (the plot and the first table) and with the crane on its own pump (the second table). Build
# first (cmake --build build). Needs python3-matplotlib.
set -euo pipefail
cd "$(dirname "$0")/.."
bin=build/app/craneassist
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
path=examples/paths/mobile_s_curve.csv
for pump in shared separate; do
  echo "== --pump $pump"
  $bin research follow $path --pump $pump --no-error-scaling --log "$out/case1_$pump.csv"
  $bin research follow $path --pump $pump --log "$out/case2_$pump.csv"
done
/usr/bin/python3 tools/plot_mobile.py "$out/case1_shared.csv" "$out/case2_shared.csv" \
  docs/img/mobile_follow.png
