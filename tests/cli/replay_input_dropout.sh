#!/bin/sh
# The input-dropout regression replay: `craneassist replay` exits 0, its summary reports the
# stop, the log's cmd columns hold nan during the stop rows and every spool is exactly 0 while
# stopped, and the tip moves again afterwards.
# Usage: replay_input_dropout.sh CRANEASSIST REPLAY_CSV WORKDIR
set -eu
bin=$1 replay=$2 work=$3
mkdir -p "$work"
"$bin" replay "$replay" --log "$work/log.csv" > "$work/summary.txt"
cat "$work/summary.txt"
grep -Eq 'stopped: [0-9]+ cycles stopping or stopped \(150 in stop rows: input not valid\), valves neutral in [1-9][0-9]*' "$work/summary.txt"
# Columns by name from the header (t, cmd_vx, tip_y, spool1..).
awk -F, 'NR == 1 { for (i = 1; i <= NF; ++i) c[$i] = i; next }
{
  t = $c["t"] + 0
  if (t >= 2.0 && t < 3.5) { if ($c["cmd_vx"] != "nan") { print "cmd not nan at t " t; bad = 1 } }
  if (t >= 3.0 && t < 3.5) {
    for (s = 1; ("spool" s) in c; ++s) if ($c["spool" s] != "0.00000") { print "spool not neutral at t " t; bad = 1 }
  }
  if (t == 3.49) y0 = $c["tip_y"]
  if (t == 5.0) y1 = $c["tip_y"]
} END {
  # Sway damping shapes the restart (docs/sway.md): 0.2 m in 1.5 s at 0.3 m/s.
  if (y1 - y0 < 0.15) { print "the tip did not go up after the stop: " y0 " -> " y1; bad = 1 }
  exit bad
}' "$work/log.csv"
echo "input dropout OK"
