#!/bin/sh
# The MCAP recording (docs/foxglove.md) read by @mcap/core (tests/foxglove/mcap_check.mjs):
#   mcap_test.sh NODE CRANEASSIST NODE_MODULES OUTDIR (the bundled demo replay, 17 s)
# 1. replay --mcap with its CSV log: the indexed and the stream reader, every CRC, the messages
#    against the CSV, the JSON channels against their schemas; uncompressed as well;
# 2. the same file with a byte flipped (in a chunk, a message index, the summary): rejected;
# 3. a real-time run killed (SIGKILL) mid-way: its complete chunks read back.
set -eu
node="$1" craneassist="$2" modules="$3" out="$4"
mkdir -p "$out"
"$craneassist" replay --mcap "$out/run.mcap" --log "$out/run.csv" | grep "mcap:"
"$node" "$(dirname "$0")/mcap_check.mjs" "$modules" "$out/run.mcap" "$out/run.csv"
"$node" "$(dirname "$0")/mcap_check.mjs" "$modules" "$out/run.mcap" "$out/run.csv" --flip
"$craneassist" replay --mcap "$out/plain.mcap" --mcap-compression none \
  --log "$out/plain.csv" >/dev/null
"$node" "$(dirname "$0")/mcap_check.mjs" "$modules" "$out/plain.mcap" "$out/plain.csv"
rm -f "$out/killed.mcap"
"$craneassist" replay --realtime --mcap "$out/killed.mcap" --log "$out/killed.csv" \
  >/dev/null 2>&1 &
pid=$!
sleep 3.5
kill -KILL "$pid"
wait "$pid" 2>/dev/null || true
echo "killed after 3.5 s: $(wc -c < "$out/killed.mcap") bytes"
"$node" "$(dirname "$0")/mcap_check.mjs" "$modules" "$out/killed.mcap" "$out/killed.csv" --truncated
echo "mcap test OK"
