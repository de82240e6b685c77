#!/usr/bin/env bash
# Regenerates docs/img/mobile_follow.png and the figures of docs/mobile.md: the crane on wheels
# on the example tool path in the paper's two cases (build first: cmake --build build). Needs
# python3-matplotlib.
set -euo pipefail
cd "$(dirname "$0")/.."
bin=build/app/craneassist
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
path=examples/paths/mobile_s_curve.csv
$bin follow $path --no-error-scaling --log "$out/case1.csv"
$bin follow $path --log "$out/case2.csv"
/usr/bin/python3 tools/plot_mobile.py "$out/case1.csv" "$out/case2.csv" docs/img/mobile_follow.png
