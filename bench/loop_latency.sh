#!/usr/bin/env bash
# Worst-case start latency of the live loop at 100 Hz (docs/realtime.md), as cyclictest measures
# it: `craneassist sim` on the simulated crane, driven back and forth for MINUTES minutes, with
# and without --rt (memory locked, SCHED_FIFO 80), on an idle machine and under stress-ng load
# (one CPU hog per core, one memory and one I/O worker). Prints the summary's timing lines.
#
#   bench/loop_latency.sh [MINUTES] [idle|loaded|all]      (default: 10 all; 40 minutes in all)
set -euo pipefail
cd "$(dirname "$0")/.."
minutes=${1:-10}
which=${2:-all}
bin=${CRANEASSIST:-build/app/craneassist}
seconds=$(awk -v m="$minutes" 'BEGIN { print int(m * 60) }')
replay=$(mktemp --suffix .csv)
trap 'rm -f "$replay"; kill $(jobs -p) 2>/dev/null || true' EXIT

# Out and up, back and down, every 4 s: the crane works all the time, within its workspace.
awk -v n=$((seconds / 4 + 1)) 'BEGIN {
  print "t,v_x,v_y,v_z";
  for (i = 0; i < n; ++i) printf "%d,%s,%s,0\n", 4 * i, (i % 2 ? "-0.3" : "0.3"), (i % 2 ? "-0.15" : "0.15");
}' >"$replay"

run() {
  local label=$1
  shift
  echo "== $label"
  "$bin" sim --input replay "$replay" --duration "$seconds" --no-telemetry "$@" 2>&1 |
    grep -E "^  (ran|cycle timing|real time)"
}

cases() {
  local load=$1
  run "$load, normal scheduler"
  run "$load, --rt (mlockall, SCHED_FIFO 80)" --rt
}

if [[ $which == idle || $which == all ]]; then cases idle; fi
if [[ $which == loaded || $which == all ]]; then
  command -v stress-ng >/dev/null || { echo "loaded: needs stress-ng (apt install stress-ng)"; exit 2; }
  stress-ng --cpu "$(nproc)" --vm 1 --vm-bytes 256M --io 1 --timeout $((2 * seconds + 60))s \
    >/dev/null 2>&1 &
  sleep 2
  cases loaded
fi
