#!/usr/bin/env bash
# Runs one libFuzzer harness for a bounded time (the fuzz_smoke and fuzz_soak tests,
# docs/fuzzing.md):
#
#   run_fuzzer.sh HARNESS SEED_CORPUS WORK_DIR SECONDS MAX_LEN
#
# The seed corpus (in the source tree) is only read; new inputs go to WORK_DIR/corpus and a
# crashing, leaking or slow input to WORK_DIR/crash-*, leak-*, timeout-* or oom-*. Fails on any
# of them; prints "fuzz run OK" and libFuzzer's closing line otherwise.
set -euo pipefail
harness="$1" seeds="$2" work="$3" seconds="$4" max_len="$5"
mkdir -p "$work/corpus"
rm -f "$work"/crash-* "$work"/leak-* "$work"/timeout-* "$work"/oom-*
log="$work/fuzz.log"
# -timeout: one input taking longer is a hang; -rss_limit_mb: a harness needing more is a bug.
status=0
"$harness" "$work/corpus" "$seeds" -max_total_time="$seconds" -max_len="$max_len" -timeout=10 \
  -rss_limit_mb=2048 -print_final_stats=1 -artifact_prefix="$work/" >"$log" 2>&1 || status=$?
if [ "$status" -ne 0 ]; then
  tail -n 80 "$log"
  echo "$(basename "$harness"): libFuzzer exited with $status; the input is in $work (see $log)"
  exit 1
fi
grep -E '^Done [0-9]+ runs|^stat::(number_of_executed_units|average_exec_per_sec|peak_rss_mb)' "$log" || true
echo "$(basename "$harness"): fuzz run OK"
