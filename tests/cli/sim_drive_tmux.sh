#!/bin/sh
# craneassist sim --drive with the keyboard in a real terminal (docs/mobile.md#live): a detached
# tmux session, keys sent with send-keys at a terminal's auto-repeat rate. With the deadman on,
# i (forward) and u (steer left) held drive the base forward and to the left while the tip
# stays; the summary names where the base ended. One pump for the drive and the crane.
# Usage: sim_drive_tmux.sh CRANEASSIST
set -eu
bin=$1
session=craneassist_drive
. "$(dirname "$0")/tmux_lib.sh"

tmux -S "$sock" new-session -d -s "$session" -x 220 -y 40 sh
keys "$bin sim --drive --pump shared --no-telemetry --log $work/drive.csv; echo DRIVE-\$((40 + 2))" Enter
wait_for "drive: i/k forward/back" 10
wait_for "base x" 5
keys Space
wait_for "deadman ON" 3
sleep 0.5
# i and u held together: each auto-repeats every 60 ms.
n=0
while [ $n -lt 50 ]; do keys i; sleep 0.03; keys u; sleep 0.03; n=$((n + 1)); done
sleep 1.0
keys q
wait_for DRIVE-42 10
pane | tail -8
line=$(pane | grep "base: at x")
echo "$line" | grep -q "one pump for the drive and the crane" || { echo "no shared pump"; exit 1; }
echo "$line" | awk '{
  x = $4 + 0; y = $7 + 0; h = $10 + 0
  ok = (x > 0.1) && (y > 0.0) && (h > 1.0)
  if (!ok) { print "the base did not drive forward and left: " $0; exit 1 }
}'
# The log has the base's columns: it ends forward and left of where it started, turned left, and
# the motors never drew more than the drive pump.
python3 - "$work/drive.csv" <<'PY' || exit 1
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
last = rows[-1]
x, y, phi = (float(last[k]) for k in ("base_x", "base_y", "base_phi"))
peak = max(float(r["base_flow_sum_m3s"]) / float(r["base_flow_max_m3s"]) for r in rows)
print(f"log: {len(rows)} rows, base at x {x:.2f} m, y {y:.2f} m, {phi:.2f} rad, peak flow ratio {peak:.3f}")
if not (x > 0.1 and y > 0.0 and phi > 0.0 and peak <= 1.0 + 1e-9):
    sys.exit("the log's base columns do not show the drive")
PY
echo "drive session OK"
