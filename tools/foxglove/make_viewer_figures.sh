#!/bin/sh
# docs/img/foxglove_viewer_recording.png and foxglove_viewer_live.png: the shipped layout in a real
# Foxglove-class viewer (a web build of Lichtblick, built outside the project: docs/foxglove.md),
# imported through its Layouts menu, with the demo replay on a pump held to 6 kW and 35 L/min (so
# power and flow reach their limits): recorded to MCAP, then live over the WebSocket server.
# tools/foxglove/viewer_check.mjs takes each screenshot and checks that every panel draws and the
# Problems tab is empty.
#   make_viewer_figures.sh LICHTBLICK_WEB_BUILD   (e.g. lichtblick/web/.webpack)
set -eu
viewer="${1:?usage: make_viewer_figures.sh LICHTBLICK_WEB_BUILD}"
root="$(cd "$(dirname "$0")/../.." && pwd)"
build="${BUILD:-$root/build}"
port="${PORT:-18799}"
work="$(mktemp -d)"
pid=""
trap '[ -n "$pid" ] && kill "$pid" 2>/dev/null; rm -rf "$work"' EXIT
pump="--prime-mover-power 6kW --pump-max-flow 35L/min"
# shellcheck disable=SC2086  # $pump: two options
"$build/app/craneassist" replay $pump --mcap "$work/run.mcap" --no-log | grep "mcap:"
node "$root/tools/foxglove/viewer_check.mjs" --viewer "$viewer" --mcap "$work/run.mcap" \
  --out "$root/docs/img/foxglove_viewer_recording"
# shellcheck disable=SC2086
"$build/app/craneassist" replay $pump --realtime --settle 30 --foxglove "127.0.0.1:$port" \
  --no-log >"$work/live.log" 2>&1 &
pid=$!
sleep 0.5
node "$root/tools/foxglove/viewer_check.mjs" --viewer "$viewer" --ws "ws://127.0.0.1:$port" --wait 6 \
  --out "$root/docs/img/foxglove_viewer_live"
