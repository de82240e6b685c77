#!/bin/sh
# craneassist dashboard in a real terminal: a detached tmux session, the screen read with
# capture-pane. Checks the waiting screen before any telemetry, the live view once
# dds_test_publisher runs (the cycle and time change between two captures, no topic stale), and
# that q and Ctrl-C end it with exit 0, the terminal settings restored and the cursor visible.
# Usage: dashboard_tmux.sh CRANEASSIST DDS_TEST_PUBLISHER DOMAIN
set -eu
# Under AddressSanitizer (CRANEASSIST_SANITIZE): Debian's Fast DDS 2.9 (not instrumented) deletes
# the statistics part of each DataReader with a mismatched size (new-delete-type-mismatch when a
# subscriber exits). Not our code; the caller's other options stay. Without the sanitizers this
# does nothing.
export ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}new_delete_type_mismatch=0"
bin=$1
publisher=$2
domain=$3
session=craneassist_dash
. "$(dirname "$0")/tmux_lib.sh"
pub_pid=
on_exit() { [ -z "$pub_pid" ] || { kill -TERM "$pub_pid" 2>/dev/null && wait "$pub_pid" 2>/dev/null; } || true; }
cursor_visible() { tmux -S "$sock" display-message -p -t "$session" '#{cursor_flag}'; }

tmux -S "$sock" new-session -d -s "$session" -x 100 -y 40 sh
keys "stty -g > $work/before.stty; $bin dashboard --domain $domain; echo EXIT1-\$?; stty -g > $work/after.stty; echo DONE1-\$((40 + 2))" Enter
wait_for "waiting for craneassist on domain $domain ..." 10
[ "$(cursor_visible)" = 0 ] || fail "the cursor is shown while the dashboard runs"

# Telemetry starts: the live view replaces the waiting screen and keeps changing.
"$publisher" "$domain" 30 > "$work/publisher.log" 2>&1 &
pub_pid=$!
wait_for "Test crane   backend sim" 10
wait_for "age       status         0." 5
pane | grep "^cycle " > "$work/first.txt" || fail "no cycle line"
sleep 0.6
pane | grep "^cycle " > "$work/second.txt" || fail "no cycle line"
cmp -s "$work/first.txt" "$work/second.txt" &&
  fail "the view did not change: $(cat "$work/first.txt")"
echo "live view: $(cat "$work/first.txt") -> $(cat "$work/second.txt")"
pane | grep -q STALE && fail "a topic shows STALE while the publisher runs"
for text in "limit     power" "12.5 /   35.0 kW" "60.0 /  120.0 L/min" "30.0 deg" "1.250 m" \
    "speed 0.50 m/s" "q or Ctrl-C quits"; do
  pane | grep -q -F -- "$text" || fail "no '$text' in the view"
done
pane
keys q
wait_for DONE1-42 5
pane | grep -q "EXIT1-0" || fail "q: not exit 0"
cmp "$work/before.stty" "$work/after.stty" || fail "terminal settings not restored after q"
[ "$(cursor_visible)" = 1 ] || fail "the cursor is hidden after q"
keys "echo-check-abc"
wait_for "echo-check-abc" 3
keys C-u

# Ctrl-C: SIGINT to the dashboard, exit 0, terminal restored. The commands run from a script
# that ignores SIGINT itself (the pane's shell may share the dashboard's process group, and
# would abandon the rest of the line on Ctrl-C).
cat > "$work/ctrl_c.sh" <<SCRIPT
trap '' INT
stty -g > $work/before2.stty
$bin dashboard --domain $domain
echo EXIT2-\$?
stty -g > $work/after2.stty
echo DONE2-\$((40 + 2))
SCRIPT
# Clear the pane first and see it cleared: the first run's last view stays on the screen, and a
# Ctrl-C sent on it (before the second dashboard runs) would reach the wrong process.
keys "clear" Enter
i=0
while pane | grep -q -F "Test crane"; do
  i=$((i + 1))
  [ $i -le 50 ] || fail "the pane was not cleared"
  sleep 0.1
done
keys "sh $work/ctrl_c.sh" Enter
wait_for "Test crane   backend sim" 10
keys C-c
wait_for DONE2-42 5
pane | grep -q "EXIT2-0" || fail "Ctrl-C: not exit 0"
cmp "$work/before2.stty" "$work/after2.stty" || fail "terminal settings not restored after Ctrl-C"
[ "$(cursor_visible)" = 1 ] || fail "the cursor is hidden after Ctrl-C"
echo "dashboard tmux session OK"
