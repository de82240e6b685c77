#!/bin/sh
# A broken input file of each format (replay, tip path, joint trajectory), through every command
# that reads it: exit code 2 and one message naming format, file, line and field.
# Usage: bad_input_files.sh CRANEASSIST DATA_DIR WORKDIR
set -u
bin=$1 data=$2 work=$3
mkdir -p "$work"
failed=0
# expect NAME MESSAGE ARGS...: craneassist ARGS must exit 2 and print MESSAGE (a fixed string).
expect() {
  name=$1 message=$2
  shift 2
  "$bin" "$@" > "$work/$name.txt" 2>&1 < /dev/null
  code=$?
  if [ "$code" -ne 2 ]; then
    echo "$name: exit code $code, expected 2"
    failed=1
  fi
  if ! grep -qF "$message" "$work/$name.txt"; then
    echo "$name: no '$message' in:"
    cat "$work/$name.txt"
    failed=1
  fi
}
replay="replay: $data/bad_replay.csv:4: field 'v_y': not a number: '0.1x'"
path="path: $data/bad_path.csv:4: field 'y': not a number: '2.O4'"
trajectory="trajectory: $data/bad_trajectory.csv:3: field 'qdot_2': not a number: 'abc'"
expect replay "$replay" replay "$data/bad_replay.csv" --no-log
expect sim_replay "$replay" sim --input replay "$data/bad_replay.csv" --no-realtime
expect bound_replay "$replay" bound "$data/bad_replay.csv"
expect plan_path "$path" plan "$data/bad_path.csv" --quiet --out "$work/plan.csv"
expect bound_path "$path" bound "$data/bad_path.csv"
expect trajectory "$trajectory" replay --trajectory "$data/bad_trajectory.csv" --no-log
[ "$failed" -eq 0 ] && echo "bad input files OK"
exit "$failed"
