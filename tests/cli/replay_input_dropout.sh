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
# Columns: t,cmd_vx(2) ... spool1..spool4 are fields NF-7..NF-4; tip_y is field 9.
awk -F, 'NR > 1 {
  t = $1 + 0
  if (t >= 2.0 && t < 3.5) { if ($2 != "nan") { print "cmd not nan at t " t; bad = 1 } }
  if (t >= 3.0 && t < 3.5) {
    for (i = NF - 7; i <= NF - 4; ++i) if ($i != "0.00000") { print "spool not neutral at t " t; bad = 1 }
  }
  if (t == 3.49) y0 = $9
  if (t == 5.0) y1 = $9
} END {
  if (y1 - y0 < 0.3) { print "the tip did not go up after the stop: " y0 " -> " y1; bad = 1 }
  exit bad
}' "$work/log.csv"
echo "input dropout OK"
