#!/bin/sh
# sim --input goal with goals typed on standard input (docs/mhsb.md#the-k70m-a-goal-for-sim):
# garbage first (bytes that are not text, a line that is not X,Z, 600 bytes without an end of
# line), then a goal with spaces, then 150 goals outside the workspace; the garbage is named and
# dropped, the typed goal is planned and reached, the goals outside are refused, and the summary
# lists the first 100 goals. Usage: sim_goal_stdin.sh CRANEASSIST TABLE
set -eu
craneassist=$1 table=$2
out=$(mktemp)
trap 'rm -f "$out"' EXIT
{
  # Typed once the run has planned its first goal (its first tip measurement): a table that is
  # still being built, or a slow (sanitizer) build, must not turn the test's goals into
  # "no tip measurement yet".
  i=0
  while ! grep -q "from the start at" "$out" 2>/dev/null && [ $i -lt 300 ]; do sleep 0.1; i=$((i + 1)); done
  printf '\377\376\001garbage\n'
  printf '4,\n'
  head -c 600 /dev/zero | tr '\0' 'x'
  sleep 1
  printf '\n'
  sleep 1
  printf ' 5.2 , 1.0 \n'
  sleep 0.5
  i=0
  while [ $i -lt 150 ]; do printf '100,100\n'; i=$((i + 1)); done  # refused, the move goes on
  sleep 8
} | "$craneassist" sim --input goal --goal 5.6,1.2 --duration 9 --no-telemetry \
  --goal-grid "0.5 m" --goal-table "$table" >"$out" 2>&1 || { cat "$out"; echo "FAIL: sim failed"; exit 1; }
fail() { cat "$out"; echo "FAIL: $*"; exit 1; }
grep -q "goal '???garbage': expected X,Z in m" "$out" || fail "the binary line was not named"
grep -q "goal '4,': expected X,Z in m" "$out" || fail "'4,' was not refused"
grep -q "goal input: [0-9]* bytes without an end of line, dropped" "$out" || fail "the long line was not dropped"
grep -q "goal (5.20, 1.00) m typed at" "$out" || fail "the typed goal was not planned"
grep -q "goal input at the end: goal reached" "$out" || fail "the typed goal was not reached"
grep -q "warning: goal (100.00, 100.00) m typed at .*: refused: the goal is outside the workspace" "$out" ||
  fail "a goal outside the workspace was not refused with a warning"
grep -q "^  (52 more goals, not listed)" "$out" || fail "the summary does not stop listing at 100 goals"
echo "typed goals OK"
