#!/bin/sh
# The DDS command input end to end (docs/remote-commands.md): `craneassist sim --input dds` on
# the simulated crane and `craneassist remote --replay` against it, with certificates made at
# test time by tools/dds-security/make-certs.sh. Each case has its own DDS domain.
#
#   valid     the operator identity: its commands pass and the tip moves
#   insecure  remote --insecure (no DDS Security): never a command, tip still
#   rogue_ca  a complete PKI of a second, unrelated CA (same names): never a command
#   forged    the operator's real certificate with permissions signed by another CA: never a
#             command
#   viewer    the viewer identity (valid certificate, may only subscribe): the remote cannot
#             create its writer (exit 3, says why), never a command
#   loss      the operator's process is killed in mid-motion: the input goes stale, the crane
#             stops (jerk-limited) and its valves go neutral
#   malformed the operator's samples turn malformed in mid-motion (a bool byte of 2, a bad
#             encapsulation, a cut-off body; dds_malformed_operator): the crane survives, counts
#             them, the input goes stale and the crane stops as on loss
#   usage     sim --input dds without commands.enabled or without the security files: exit 2
#             with the message; remote without an identity: exit 2
#
# Usage: remote_commands.sh CASE CRANEASSIST MAKE_CERTS REPLAY_CSV DOMAIN WORKDIR [HELPER]
#   HELPER: malformed: the dds_malformed_operator program
# Prints "CASE OK" on success. The sim's loop runs at SCHED_FIFO priority 80 where the test may
# have it (as root, as CI runs; without it a warning and the default policy), as on a machine: a
# busy host must not stall the loop until the operator's input goes stale. Not --rt: locking all
# memory under AddressSanitizer would fault in its shadow.
set -eu
case_name=$1 bin=$2 make_certs=$3 replay=$4 domain=$5 work=$6 helper=${7:-}
# Under AddressSanitizer (CRANEASSIST_SANITIZE): Debian's Fast DDS 2.9 deletes its statistics
# listeners with a mismatched size (new-delete-type-mismatch at every participant's teardown) and
# leaks OpenSSL objects on a failed handshake (tests/lsan-fastdds.supp). Both are in the library,
# not instrumented; the caller's other options stay. Without the sanitizers these do nothing.
export ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}new_delete_type_mismatch=0"
tests_dir=$(cd "$(dirname "$0")/.." && pwd)
export LSAN_OPTIONS="${LSAN_OPTIONS:+$LSAN_OPTIONS:}suppressions=$tests_dir/lsan-fastdds.supp"
rm -rf "$work"
mkdir -p "$work"
fail() {
  echo "FAIL ($case_name): $*"
  for f in "$work"/*.out; do
    [ -f "$f" ] && { echo "--- $f"; cat "$f"; }
  done
  exit 1
}

# expect_usage_error NAME PATTERN ARGS...: craneassist ARGS must exit 2 (a usage error) and its
# output ($work/NAME.out) match the grep PATTERN.
expect_usage_error() {
  name=$1 pattern=$2
  shift 2
  rc=0
  "$bin" "$@" >"$work/$name.out" 2>&1 || rc=$?
  [ "$rc" -eq 2 ] || fail "$name: craneassist $* exited $rc"
  grep -q "$pattern" "$work/$name.out" || fail "message: $name"
}

# sim_remote REMOTE_YAML_OR_--insecure [REMOTE_EXIT]: runs the crane for $duration s with the DDS
# input and the remote with the replay against it; REMOTE_EXIT is the remote's expected exit code.
# The remote waits at most $wait s for the crane's reader before it plays the replay anyway
# (discovery with the DDS Security handshake takes 0.02 .. 2 s).
wait=1 duration=4
sim_remote() {
  remote_arg=$1 remote_exit=${2:-0}
  "$bin" sim --rt-priority 80 --input dds --telemetry-config "$work/certs/crane.yaml" --domain "$domain" \
    --duration "$duration" --log "$work/log.csv" >"$work/sim.out" 2>&1 &
  sim_pid=$!
  if [ "$remote_arg" = "--insecure" ]; then
    set -- --insecure
  else
    set -- --telemetry-config "$remote_arg"
  fi
  rc=0
  "$bin" remote "$@" --domain "$domain" --replay "$replay" --wait "$wait" --sender "test-$case_name" \
    >"$work/remote.out" 2>&1 || rc=$?
  sim_rc=0
  wait "$sim_pid" || sim_rc=$?
  [ "$sim_rc" -eq 0 ] || fail "sim exited $sim_rc"
  [ "$rc" -eq "$remote_exit" ] || fail "remote exited $rc, expected $remote_exit"
  passed=$(sed -n 's/.*operator command passed in \([0-9]*\) cycles.*/\1/p' "$work/sim.out")
  [ -n "$passed" ] || fail "no summary from sim"
  # Tip displacement over the run, from the log (tip_x, tip_y, tip_z: columns 8-10).
  moved=$(awk -F, 'NR == 2 { x = $8; y = $9; z = $10 }
                   NR > 2 { dx = $8 - x; dy = $9 - y; dz = $10 - z }
                   END { printf "%.3f", sqrt(dx * dx + dy * dy + dz * dz) }' "$work/log.csv")
  commanded=$(awk -F, 'NR > 1 && $2 != "nan" && ($2 != 0 || $3 != 0 || $4 != 0) { n++ }
                       END { print n + 0 }' "$work/log.csv")
}

# From the log (t: column 1, cmd_vx: 2, tip_vx..tip_vz: 11..13, spool*): the last cycle the
# command passed, the first cycle after it with every valve neutral, the peak tip speed and the tip
# speed at the end; checks that the crane moved, then stopped with every valve neutral.
expect_moved_then_stopped() {
  result=$(awk -F, '
    NR == 1 { for (i = 1; i <= NF; i++) if ($i ~ /^spool/) spool[++n] = i; next }
    {
      neutral = 1
      for (k = 1; k <= n; k++) if ($spool[k] != 0) neutral = 0
      v = sqrt($11 * $11 + $12 * $12 + $13 * $13)
      if ($2 != "nan") { last = $1; rest = -1; if (v > peak) peak = v }
      else if (neutral && rest < 0 && last != "") rest = $1
      end_v = v
    }
    END { printf "%s %s %.3f %.4f", last, rest, peak, end_v }' "$work/log.csv")
  # shellcheck disable=SC2086 # four words
  set -- $result
  [ -n "${1:-}" ] || fail "the command never passed"
  awk -v p="$3" 'BEGIN { exit !(p > 0.1) }' || fail "the tip never moved (peak $3 m/s)"
  awk -v r="$2" 'BEGIN { exit !(r > 0) }' || fail "the valves never went neutral"
  awk -v v="$4" 'BEGIN { exit !(v < 0.01) }' || fail "the tip still moves at the end ($4 m/s)"
  stop_summary="last command at t $1 s, every valve neutral at t $2 s, peak tip speed $3 m/s, at the end $4 m/s"
}

expect_no_command() {
  [ "$passed" -eq 0 ] || fail "the operator command passed in $passed cycles"
  [ "$commanded" -eq 0 ] || fail "$commanded log rows with a command"
  awk -v m="$moved" 'BEGIN { exit !(m < 0.01) }' || fail "the tip moved $moved m"
  grep -q "dds input: 0 samples" "$work/sim.out" || fail "the DDS input got samples"
}

case $case_name in
  valid)
    "$make_certs" "$work/certs" >/dev/null
    wait=5 duration=7
    sim_remote "$work/certs/operator.yaml"
    [ "$passed" -gt 0 ] || fail "the operator command never passed"
    [ "$commanded" -gt 0 ] || fail "no log row with a command"
    awk -v m="$moved" 'BEGIN { exit !(m > 0.1) }' || fail "the tip moved only $moved m"
    grep -q "crane reader matched: yes" "$work/remote.out" || fail "the remote saw no crane"
    grep -q "samples from 'test-valid'" "$work/sim.out" || fail "sim does not name the sender"
    echo "sim: $(grep 'operator command passed' "$work/sim.out")"
    echo "sim: $(grep 'dds input: [0-9]' "$work/sim.out")"
    echo "remote: $(grep 'crane reader matched' "$work/remote.out")"
    echo "tip moved $moved m, $commanded commanded cycles"
    ;;
  insecure)
    "$make_certs" "$work/certs" >/dev/null
    sim_remote --insecure
    expect_no_command
    grep -q "WITHOUT DDS Security" "$work/remote.out" || fail "the remote did not warn"
    grep -q "crane reader matched: no" "$work/remote.out" || fail "a reader matched"
    ;;
  rogue_ca)
    "$make_certs" "$work/certs" >/dev/null
    "$make_certs" --ca-name "rogue CA" "$work/rogue" >/dev/null
    sim_remote "$work/rogue/operator.yaml"
    expect_no_command
    grep -q "crane reader matched: no" "$work/remote.out" || fail "a reader matched"
    ;;
  forged)
    "$make_certs" "$work/certs" >/dev/null
    "$make_certs" --ca-name "rogue CA" "$work/rogue" >/dev/null
    # The operator's real identity, with permissions (and governance) signed by the rogue CA.
    cat >"$work/forged.yaml" <<EOF
format: craneassist-telemetry/1
commands:
  enabled: true
  security:
    identity_ca: certs/ca.pem
    identity_certificate: certs/operator.pem
    private_key: certs/operator.key
    permissions_ca: rogue/ca.pem
    governance: rogue/governance.p7s
    permissions: rogue/operator-permissions.p7s
EOF
    sim_remote "$work/forged.yaml"
    expect_no_command
    grep -q "crane reader matched: no" "$work/remote.out" || fail "a reader matched"
    ;;
  viewer)
    "$make_certs" "$work/certs" >/dev/null
    sim_remote "$work/certs/viewer.yaml" 3
    expect_no_command
    grep -q "permissions do not allow publishing" "$work/remote.out" || fail "no reason given"
    ;;
  loss)
    "$make_certs" "$work/certs" >/dev/null
    "$bin" sim --rt-priority 80 --input dds --telemetry-config "$work/certs/crane.yaml" --domain "$domain" \
      --duration 5 --log "$work/log.csv" >"$work/sim.out" 2>&1 &
    sim_pid=$!
    "$bin" remote --telemetry-config "$work/certs/operator.yaml" --domain "$domain" \
      --replay "$replay" --sender test-loss >"$work/remote.out" 2>&1 &
    remote_pid=$!
    # Once the crane names the operator, the motion runs for 1 s; then the operator's process
    # dies without a goodbye (its writer stays matched until the DDS lease runs out).
    i=0
    until grep -q "remote operator: 'test-loss'" "$work/sim.out"; do
      i=$((i + 1))
      [ "$i" -lt 100 ] || fail "no operator within 10 s"
      sleep 0.1
    done
    sleep 1
    kill -KILL "$remote_pid"
    wait "$remote_pid" || true
    wait "$sim_pid" || fail "sim exited $?"
    grep -q "input stale" "$work/sim.out" || fail "no stale input reported"
    expect_moved_then_stopped
    echo "loss: $stop_summary"
    ;;
  malformed)
    [ -x "$helper" ] || fail "no dds_malformed_operator given"
    "$make_certs" "$work/certs" >/dev/null
    "$bin" sim --rt-priority 80 --input dds --telemetry-config "$work/certs/crane.yaml" --domain "$domain" \
      --duration 6 --log "$work/log.csv" >"$work/sim.out" 2>&1 &
    sim_pid=$!
    rc=0
    "$helper" "$domain" "$work/certs/operator.yaml" >"$work/operator.out" 2>&1 || rc=$?
    sim_rc=0
    wait "$sim_pid" || sim_rc=$?
    [ "$rc" -eq 0 ] || fail "dds_malformed_operator exited $rc"
    [ "$sim_rc" -eq 0 ] || fail "sim exited $sim_rc (killed by a malformed sample?)"
    grep -q "input stale" "$work/sim.out" || fail "no stale input reported"
    grep -q "malformed, 0 replayed samples dropped so far" "$work/sim.out" ||
      fail "no malformed samples reported"
    bad=$(sed -n 's/.*dds input: .* \([0-9]*\) malformed,.*/\1/p' "$work/sim.out")
    [ -n "$bad" ] && [ "$bad" -gt 50 ] || fail "malformed samples counted: '$bad' (sent 100)"
    expect_moved_then_stopped
    echo "malformed: $bad malformed samples counted; $stop_summary"
    ;;
  usage)
    "$make_certs" "$work/certs" >/dev/null
    # The default settings (commands.enabled false).
    expect_usage_error default "commands.enabled is not true" sim --input dds --duration 1
    grep -q "docs/remote-commands.md" "$work/default.out" || fail "no pointer to the docs"
    sed 's/enabled: true/enabled: false/' "$work/certs/crane.yaml" >"$work/certs/disabled.yaml"
    expect_usage_error disabled "commands.enabled is not true" \
      sim --input dds --telemetry-config "$work/certs/disabled.yaml" --duration 1
    # A security file missing.
    grep -v "permissions:" "$work/certs/crane.yaml" >"$work/certs/partial.yaml"
    expect_usage_error partial "partial.yaml:[0-9]*: field 'commands.security': give every file" \
      sim --input dds --telemetry-config "$work/certs/partial.yaml" --duration 1
    # No security files at all.
    sed -e 's/^  security:$/  security: {}/' -e '/^    /d' "$work/certs/crane.yaml" \
      >"$work/certs/nosecurity.yaml"
    expect_usage_error nosecurity \
      "nosecurity.yaml:[0-9]*: field 'commands.enabled': the DDS command input needs DDS Security" \
      sim --input dds --telemetry-config "$work/certs/nosecurity.yaml" --duration 1
    # The remote without an identity.
    expect_usage_error remote "needs the operator's DDS Security identity" \
      remote --replay "$replay" --domain "$domain"
    ;;
  *)
    echo "unknown case $case_name" >&2
    exit 2
    ;;
esac
echo "$case_name OK"
