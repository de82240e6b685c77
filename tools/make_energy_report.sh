#!/usr/bin/env bash
# Paper 000's energy experiment in simulation: builds craneassist, runs every redundancy
# resolution on every test path from both start configurations with a load-sensing and a
# constant-pressure pump, and writes the measured energies into docs/energy.md and the bar chart
# docs/img/energy.png. About 5 minutes on 2 cores (the DP planner on the paper's grid dominates).
set -euo pipefail
cd "$(dirname "$0")/.."
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j"$(nproc)" --target craneassist
mkdir -p build/energy docs/img
./build/app/craneassist research energy --out build/energy/results.csv "$@"
/usr/bin/python3 tools/energy_report.py build/energy/results.csv docs/energy.md docs/img/energy.png
