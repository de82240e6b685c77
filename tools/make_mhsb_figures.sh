#!/usr/bin/env bash
# Regenerates paper 001's results on our MHSB arm (docs/mhsb.md#the-papers-results-compared):
# runs every case of the paper with `craneassist research ptp` (planned, and on the MHSB simulator), writes
# docs/data/mhsb_cases.csv, the figures docs/img/mhsb_*.png and the table in docs/mhsb.md made
# from that file. Build first (cmake --build build);
# needs python3-matplotlib. About a minute with the posture tables cached (~/.cache/craneassist;
# each table missing takes 10 to 20 s to build).
set -euo pipefail
cd "$(dirname "$0")/.."
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
/usr/bin/python3 tools/mhsb_cases.py --bin build/app/craneassist --work "$work" \
  --out docs/data/mhsb_cases.csv "$@"
/usr/bin/python3 tools/plot_mhsb.py "$work" docs/data/mhsb_cases.csv docs/img --doc docs/mhsb.md
