#!/bin/sh
# craneassist echo and craneassist dashboard from the command line, against dds_test_publisher
# (synthetic telemetry, tests/dds_test_frames.hpp): exit codes, messages, output.
# Usage: dds_tools.sh CASE CRANEASSIST DDS_TEST_PUBLISHER DOMAIN
#   CASE: echo | usage | timeout | dashboard | signal | fields (against craneassist replay itself)
set -eu
. "$(dirname "$0")/test_lib.sh"
case_name=$1
bin=$2
publisher=$3
domain=$4
# expect RC COMMAND...: runs the command, stdout to $work/out, stderr to $work/err.
expect() {
  want=$1
  shift
  rc=0
  "$@" > "$work/out" 2> "$work/err" || rc=$?
  [ "$rc" = "$want" ] || { cat "$work/out" "$work/err"; fail "$*: exit $rc, expected $want"; }
}
start_publisher() {
  "$publisher" "$domain" 20 > "$work/publisher.log" 2>&1 &
  bg_pid=$!
}

case $case_name in
echo)
  start_publisher
  # Every telemetry topic (the test frame's values in each; the DDS name works too) and a CSV,
  # all at once: each echo's discovery can take a few seconds (more under the sanitizers with
  # other DDS tests running: 15 s each, well inside the publisher's 20 s).
  n=0
  pids=
  for topic in status craneassist/joints hydraulics command_path csv; do
    n=$((n + 1))
    if [ "$topic" = csv ]; then
      set -- echo hydraulics --count 2 --format csv
    else
      set -- echo "$topic" --count 3
    fi
    (rc=0; "$bin" "$@" --domain "$domain" --timeout 15 > "$work/out$n" 2> "$work/err$n" || rc=$?
     echo "$rc" > "$work/rc$n") &
    pids="$pids $!"
  done
  # shellcheck disable=SC2086 # one pid a word
  wait $pids
  n=0
  for topic in status craneassist/joints hydraulics command_path csv; do
    n=$((n + 1))
    mv "$work/out$n" "$work/out"
    mv "$work/err$n" "$work/err"
    [ "$(cat "$work/rc$n")" = 0 ] || { cat "$work/out" "$work/err"; fail "$topic: exit $(cat "$work/rc$n")"; }
    has err "discovered 1 writer after"
    has err "receiving, first sample after"
    [ $topic = csv ] && break
    [ "$(grep -c '^---$' "$work/out")" = 3 ] || { cat "$work/out"; fail "$topic: not 3 samples"; }
    case $topic in
      status) has out "active_limit: power" ;;
      */joints) has out "q: [0.523599 rad, 0.349066 rad, -0.785398 rad, 1.25 m]" ;;
      hydraulics) has out "power_limit_w: 35000 W" ;;
      command_path) has out "reference_m_s: [0.3, 0.4, 0] m/s" ;;
    esac
  done
  [ "$(wc -l < "$work/out")" = 3 ] || { cat "$work/out"; fail "csv: not a header and 2 rows"; }
  head -1 "$work/out" | grep -q "^cycle,t_s,stamp_ns,pump_mode,flow_m3_s,pressure_pa,power_w," ||
    fail "csv header: $(head -1 "$work/out")"
  col=$(head -1 "$work/out" | tr , '\n' | grep -n '^power_w$' | cut -d: -f1)
  [ "$(sed -n 3p "$work/out" | cut -d, -f"$col")" = 12500 ] || fail "csv power_w: $(cat "$work/out")"
  # No diagnostics on stdout: the csv can go straight to a file.
  grep -q "discovered\|receiving" "$work/out" && fail "discovery message on stdout"
  echo "echo OK"
  ;;
usage)
  expect 2 "$bin" echo warp --count 1
  has err "unknown topic 'warp'; the topics: status, joints, hydraulics, command_path, operator_command"
  expect 2 "$bin" echo status --format xml
  expect 2 "$bin" echo
  expect 2 "$bin" dashboard --domain 300
  # A bad settings file: file, line and field, exit 2 before DDS starts.
  printf 'format: craneassist-telemetry/1\ntype_propagation:\n  type_information: maybe\n' \
    > "$work/bad.yaml"
  for tool in "echo status" dashboard; do
    # shellcheck disable=SC2086 # the tool and its topic
    expect 2 "$bin" $tool --telemetry-config "$work/bad.yaml"
    has err "bad.yaml:3: field 'type_propagation.type_information': expected true or false"
  done
  echo "usage OK"
  ;;
timeout)
  expect 3 "$bin" echo status --domain "$domain" --timeout 1
  has err "no sample on craneassist/status within 1 s on domain $domain; is craneassist sim running with telemetry on?"
  expect 3 "$bin" dashboard --once --domain "$domain" --timeout 1
  has err "no sample on craneassist/status, craneassist/joints, craneassist/hydraulics, craneassist/command_path within 1 s on domain $domain"
  echo "timeout OK"
  ;;
dashboard)
  start_publisher
  expect 0 "$bin" dashboard --once --domain "$domain" --timeout 8
  for text in "Test crane   backend sim" "limit     power" "12.5 /   35.0 kW      36 %" \
      "60.0 /  120.0 L/min   50 %" "slew            30.0 deg" "extension      1.250 m" \
      "speed 0.50 m/s"; do
    has out "$text"
  done
  grep -q "$(printf '\033')" "$work/out" && fail "escape codes in the snapshot"
  # Not a terminal: one plain snapshot without --once too.
  expect 0 "$bin" dashboard --domain "$domain" --timeout 8
  [ "$(grep -c "^craneassist dashboard" "$work/out")" = 1 ] || fail "not one snapshot"
  has out "pump limiter  none"
  echo "dashboard OK"
  ;;
fields)
  # The field table on DDS (craneassist/fields) from a real run: echo prints every value by name
  # with its unit, dashboard --fields shows them.
  "$bin" replay --telemetry --domain "$domain" --realtime --no-log > "$work/replay.log" 2>&1 &
  bg_pid=$!
  expect 0 "$bin" echo fields --domain "$domain" --count 1 --timeout 15
  for text in "cycle:" "q.2: " " rad" "pump_power_w: " " W" "load_moment_ratio: " "deadman: "; do
    has out "$text"
  done
  expect 0 "$bin" dashboard --once --fields --domain "$domain" --timeout 15
  for text in "craneassist dashboard" "pump_pressure_pa" "Pa" "payload_estimate_kg" "q_ref.4"; do
    has out "$text"
  done
  echo "fields OK"
  ;;
signal)
  # Waiting for samples forever: SIGTERM and SIGINT end it with exit 0.
  for sig in TERM INT; do
    "$bin" echo status --domain "$domain" > "$work/out" 2> "$work/err" &
    pid=$!
    sleep 1
    kill -"$sig" "$pid"
    rc=0
    wait "$pid" || rc=$?
    [ "$rc" = 0 ] || { cat "$work/err"; fail "SIG$sig: exit $rc"; }
  done
  echo "signal OK"
  ;;
*)
  fail "unknown case $case_name"
  ;;
esac
