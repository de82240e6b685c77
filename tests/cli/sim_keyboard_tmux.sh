#!/bin/sh
# craneassist sim --input keyboard in a real terminal: a detached tmux session, keys sent with
# send-keys, the screen read with capture-pane. Checks that the deadman and a held key (sent at
# a terminal's auto-repeat rate) move the tip the commanded way, that q quits, that SIGTERM
# stops it, and that the terminal settings are restored both times.
# Usage: sim_keyboard_tmux.sh CRANEASSIST
set -eu
bin=$1
session=craneassist_kb
. "$(dirname "$0")/tmux_lib.sh"
# hold KEY SECONDS: the key as a terminal sends it while held (auto-repeat every 30 ms).
hold() {
  n=$(awk "BEGIN { print int($2 / 0.03) }")
  i=0
  while [ $i -lt $n ]; do keys "$1"; sleep 0.03; i=$((i + 1)); done
}

tmux -S "$sock" new-session -d -s "$session" -x 200 -y 40 sh
keys "stty -g > $work/before.stty; $bin sim --input keyboard --log $work/kb.csv; stty -g > $work/after.stty; echo SESSION1-\$((40 + 2))" Enter
wait_for "keys: space deadman" 10
wait_for "stopped" 5
hold w 0.5  # a key without the deadman: nothing moves
pane | tail -1 | grep -q "stopped .*deadman off.* 0.00 m/s | deadman released" ||
  { echo "moved without the deadman:"; pane | tail -1; exit 1; }
keys Space
wait_for "deadman ON" 3
hold w 2.0        # reach out
sleep 0.3
hold r 1.0        # then up
wait_for "running" 1
pane | tail -3
sleep 1.5
keys q
wait_for SESSION1-42 10
pane | tail -12
cmp "$work/before.stty" "$work/after.stty" || { echo "terminal settings not restored after q"; exit 1; }
# Echo is back on: typed text appears on the screen.
keys "echo-check-abc"
wait_for "echo-check-abc" 3
keys C-u

# The log: at rest before the deadman; out (x) while w was held, then up (y); no slew (z).
awk -F, -v out="$work/moves.txt" '
  NR == 1 { next }
  NR == 2 { x0 = $8; y0 = $9; z0 = $10 }
  $1 <= 0.4 && ($11 * $11 + $12 * $12 + $13 * $13) > 1e-6 { early = 1 }
  { x = $8; y = $9; z = $10; vx = $11; vy = $12
    if (vx > peak_vx) peak_vx = vx
    if (vy > peak_vy) peak_vy = vy }
  END {
    printf "tip moved dx %.3f dy %.3f dz %.3f m; peak vx %.3f vy %.3f m/s\n", x - x0, y - y0, z - z0, peak_vx, peak_vy
    ok = (x - x0 > 0.3) && (y - y0 > 0.1) && (z - z0 < 0.02) && (z0 - z < 0.02) && !early
    print ok > out
  }' "$work/kb.csv"
[ "$(cat "$work/moves.txt")" = 1 ] || { echo "the crane did not move as commanded"; exit 1; }

# SIGTERM while the deadman is on: stops, restores the terminal. The screen cleared first, so
# the waits below see the second run's lines, not the first's (on a busy machine the second run
# starts later than its keys are sent).
keys "clear" Enter
wait_for_gone "keys: space deadman" 10
keys "stty -g > $work/before2.stty; sh -c 'echo \$\$ > $work/pid; exec $bin sim --input keyboard'; stty -g > $work/after2.stty; echo SESSION2-\$((40 + 2))" Enter
wait_for "keys: space deadman" 10
keys Space
wait_for "deadman ON" 3
[ -s "$work/pid" ] || fail "no pid file from the second run"
kill -TERM "$(cat "$work/pid")"
wait_for SESSION2-42 10
cmp "$work/before2.stty" "$work/after2.stty" || { echo "terminal settings not restored after SIGTERM"; exit 1; }
pane | grep -q "craneassist sim: keyboard input" || { echo "no summary after SIGTERM"; pane; exit 1; }
echo "keyboard session OK"
