#!/bin/sh
# Runs a browser test of the web view (tests/web/*.mjs) when Chromium is there; otherwise exits
# 77 (CTest: skipped), or fails when CRANEASSIST_WEB_REQUIRED=1 (CI, tools/test.sh).
#   run_web_test.sh NODE SCRIPT CRANEASSIST NODE_MODULES [ARGS...]
node="$1"
shift
chromium="${CHROMIUM:-/usr/bin/chromium}"
if [ ! -x "$chromium" ] || [ -z "$node" ]; then
  echo "web test: no Chromium at $chromium or no node (run tools/install-deps.sh)"
  [ "${CRANEASSIST_WEB_REQUIRED:-0}" = 1 ] && exit 2
  exit 77
fi
exec "$node" "$@"
