#!/bin/sh
# `craneassist web` against a run whose status topic is best-effort and volatile (another
# telemetry settings file): the watcher's reliable, transient-local status reader cannot match
# it, and `web` must say so; given the run's settings it matches and shows the run's end
# (docs/web.md#watching-a-run). Usage: web_watch_status_qos.sh CRANEASSIST REPLAY DOMAIN
set -eu
. "$(dirname "$0")/test_lib.sh"
craneassist=$1 replay=$2 domain=$3
sed '/^  status:/,/depth/{s/reliability: reliable/reliability: best_effort/;s/durability: transient_local/durability: volatile/}' \
  "$(dirname "$0")/../../config/telemetry/default.yaml" >"$work/best_effort.yaml"
grep -q "reliability: best_effort" "$work/best_effort.yaml" || fail "sed did not edit the status topic"

# watch_case NAME [web options...]: web watches one replay with best-effort status, until the
# replay has ended and web has said so (or 10 s more: on a busy machine the run starts and ends
# later than on an idle one, and a fixed --duration cut it short), then is stopped with SIGINT.
watch_case() {
  name=$1
  shift
  "$craneassist" web --web-listen 127.0.0.1:0 --domain "$domain" --duration 120 "$@" >"$work/$name.txt" 2>&1 &
  bg_pid=$!
  sleep 1
  "$craneassist" replay "$replay" --realtime --telemetry --telemetry-config "$work/best_effort.yaml" \
    --domain "$domain" --no-log >"$work/$name-replay.txt" 2>&1 || fail "replay failed"
  i=0
  while [ $i -lt 100 ] && ! grep -q "the watched run stopped\|before it said it stopped" "$work/$name.txt"; do
    sleep 0.1
    i=$((i + 1))
  done
  kill -INT "$bg_pid"
  wait "$bg_pid" || { cat "$work/$name.txt"; fail "web failed"; }
  bg_pid=
}

watch_case default
has default.txt "publishes its status with a QoS that does not give the reliable, transient_local status"
has default.txt "give \`web\` the run's --telemetry-config"

watch_case matched --telemetry-config "$work/best_effort.yaml"
has matched.txt "the watched run stopped: end of run"
if grep -q "does not give" "$work/matched.txt"; then cat "$work/matched.txt"; fail "warned with matching settings"; fi
echo "ok: web names an unmatched status QoS, and with the run's settings shows its end"
