#!/bin/sh
# A live session from a replay file, recorded, then the recording replayed: the two per-cycle
# logs must be identical byte for byte. With stop rows in the input (an input dropout) the
# recording holds stop rows too, and both logs the stop with neutral valves.
# Usage: sim_record_replay.sh CRANEASSIST REPLAY_CSV WORKDIR
set -eu
bin=$1 replay=$2 work=$3
mkdir -p "$work"
"$bin" sim --input replay "$replay" --no-realtime --log "$work/live.csv" --record "$work/rec.csv"
"$bin" replay "$work/rec.csv" --settle 0 --log "$work/replayed.csv"
cmp "$work/live.csv" "$work/replayed.csv"
stops=$(grep -c ',1$' "$work/rec.csv" || true)
if head -1 "$work/rec.csv" | grep -q ',stop$'; then :; else stops=0; fi
echo "logs identical: $(wc -l < "$work/live.csv") lines, recording $(wc -l < "$work/rec.csv") lines, stop rows $stops"
