#!/usr/bin/env bash
# Regenerates the figures and tables of docs/mobile.md: the crane on wheels on the example tool
# path in paper 003's two cases, on the paper's machine (drive and crane on separate circuits:
# docs/img/mobile_follow.png and the first table), with a sluggish arm (the measured cause of the
# difference to the paper's figure 6: the second table) and with one pump for the drive and the
# crane, craneassist's own addition (docs/img/mobile_follow_shared.png and the third table).
# Build first (cmake --build build). Needs python3-matplotlib.
set -euo pipefail
cd "$(dirname "$0")/.."
bin=build/app/craneassist
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
/usr/bin/python3 tools/mobile_cases.py "$bin" "$out" --doc docs/mobile.md
/usr/bin/python3 tools/plot_mobile.py "$out/separate_case1.csv" "$out/separate_case2.csv" \
  docs/img/mobile_follow.png
/usr/bin/python3 tools/plot_mobile.py "$out/shared_case1.csv" "$out/shared_case2.csv" \
  docs/img/mobile_follow_shared.png
