#!/usr/bin/env bash
# How the crane stops at the end of a run: 7 motions x 4 endings, measured from the per-cycle logs.
#
# Usage: tools/stop_figures.sh BINARY OUTDIR
#   BINARY  a built craneassist (e.g. build/app/craneassist)
#   OUTDIR  created if missing: OUTDIR/replays/ the generated replays, OUTDIR/logs/ the logs
#           (ID-ENDING.csv) with each run's console output (.out) and exit code (.rc),
#           OUTDIR/manifest.tsv, OUTDIR/stop_figures.md the table (earlier files overwritten)
# The example replays are read from the repository this script is in (it changes there).
#
# Motions: the six axis pushes of the operator-feel suite (examples/replays/suite/push_*.csv,
# 0.6 m/s from 0.5 s), cut at T = 3.0 s, and the heavy lift (examples/replays/heavy_lift.csv,
# --payload 650), cut at T = 2.5 s in its fast motion (tip at ~1.3 m/s).
# Endings:
#   replay end       replay M-end.csv --settle 0   (the file ends at T with the stick pushed)
#   stop row         replay M-stop.csv --settle 0  (a stop row at T, the last one at T + 4 s)
#   deadman release  sim --input replay M-stop.csv --no-realtime --no-telemetry
#   SIGINT           timeout -k 20 -s INT T sim --input replay M-hold.csv --no-telemetry (real
#                    time: these 7 runs go in the background, launched 0.4 s apart, env
#                    STOP_FIGURES_STAGGER, while the others run; -k 20: SIGKILL if it hangs)
# --payload 650 goes to every heavy-lift run. Takes ~10 s.
# Prints the Markdown table (tools/stop_figures.py report) and saves it to OUTDIR/stop_figures.md.
# Exits non-zero if a run fails or a log cannot be measured (the table then says `error`).
set -euo pipefail

if [[ $# -ne 2 || $1 == -h || $1 == --help ]]; then
  sed -n '2,23p' "$0" | sed 's/^# \{0,1\}//' >&2
  exit 2
fi
bin=$1
out=$2
here=$(cd "$(dirname "$0")" && pwd)
root=$(dirname "$here")
py="$here/stop_figures.py"

given=$bin
if [[ $bin != */* ]]; then bin=$(command -v "$bin" || true); fi
[[ -n $bin && -f $bin && -x $bin ]] ||
  { echo "stop_figures.sh: $given: not an executable file" >&2; exit 1; }
bin=$(cd "$(dirname "$bin")" && pwd)/$(basename "$bin")
mkdir -p "$out"
out=$(cd "$out" && pwd)
mkdir -p "$out/replays" "$out/logs"
cd "$root"

# The options this script relies on must exist in this binary.
replay_help=$("$bin" replay --help 2>&1) || true
sim_help=$("$bin" sim --help 2>&1) || true
for opt in --settle --log --payload; do
  grep -q -- "$opt" <<<"$replay_help" ||
    { echo "stop_figures.sh: $bin replay has no $opt option (see its --help)" >&2; exit 1; }
done
for opt in --input --no-realtime --no-telemetry --log --payload; do
  grep -q -- "$opt" <<<"$sim_help" ||
    { echo "stop_figures.sh: $bin sim has no $opt option (see its --help)" >&2; exit 1; }
done

# id | source replay | cut time T [s] | payload [kg] | label
motions=(
  "push_x_plus|examples/replays/suite/push_x_plus.csv|3.0||push +x (out), T = 3.0 s"
  "push_x_minus|examples/replays/suite/push_x_minus.csv|3.0||push −x (in), T = 3.0 s"
  "push_y_plus|examples/replays/suite/push_y_plus.csv|3.0||push +y (up), T = 3.0 s"
  "push_y_minus|examples/replays/suite/push_y_minus.csv|3.0||push −y (down), T = 3.0 s"
  "push_z_plus|examples/replays/suite/push_z_plus.csv|3.0||push +z (side), T = 3.0 s"
  "push_z_minus|examples/replays/suite/push_z_minus.csv|3.0||push −z (side), T = 3.0 s"
  "heavy_lift|examples/replays/heavy_lift.csv|2.5|650|heavy lift 650 kg, T = 2.5 s (mid fast lift)"
)

manifest="$out/manifest.tsv"
printf 'motion\tlabel\tcut_s\tending\tlog\tconsole\trc\n' >"$manifest"

# run ID ENDING LOG CMD...: runs CMD with its output in LOG's .out, records the exit code.
run() {
  local id=$1 ending=$2 log=$3
  shift 3
  local rc=0
  rm -f "$log"
  "$@" >"${log%.csv}.out" 2>&1 || rc=$?
  printf '%s\t%s\n' "$ending" "$rc" >"${log%.csv}.rc"
}

declare -A label cut pay
ids=()
cuts=()
for m in "${motions[@]}"; do
  IFS='|' read -r id src T payload lab <<<"$m"
  ids+=("$id")
  label[$id]=$lab
  cut[$id]=$T
  pay[$id]=$payload
  cuts+=("$src" "$T" "$out/replays/$id")
done
python3 "$py" cut "${cuts[@]}"

# payload_args ID: sets pargs to the run's --payload option (none for the pushes).
payload_args() {
  pargs=()
  if [[ -n ${pay[$1]} ]]; then pargs=(--payload "${pay[$1]}"); fi
}

# SIGINT runs: real time, in the background (each needs ~2 % of a core once running), launched
# from a background subshell while the others run. The launches are staggered: a sim's start-up
# is CPU-bound, and seven at once on two cores delay the loop's start by up to ~1 s, so the signal
# would come that much earlier in the run's machine time than T.
sigint_runs() {
  local id first=1
  for id in "${ids[@]}"; do
    [[ $first -eq 1 ]] || sleep "${STOP_FIGURES_STAGGER:-0.4}"
    first=0
    payload_args "$id"
    run "$id" SIGINT "$out/logs/$id-sigint.csv" timeout -k 20 -s INT "${cut[$id]}" \
      "$bin" sim --input replay "$out/replays/$id-hold.csv" --no-telemetry \
      --log "$out/logs/$id-sigint.csv" "${pargs[@]}" &
  done
  wait
}
sigint_runs &
sigint_pid=$!

# The others, as fast as possible (niced: the real-time runs start sooner after their launch).
for id in "${ids[@]}"; do
  payload_args "$id"
  run "$id" "replay end" "$out/logs/$id-replay-end.csv" \
    nice -n 10 "$bin" replay "$out/replays/$id-end.csv" --settle 0 \
    --log "$out/logs/$id-replay-end.csv" "${pargs[@]}"
  run "$id" "stop row" "$out/logs/$id-stop-row.csv" \
    nice -n 10 "$bin" replay "$out/replays/$id-stop.csv" --settle 0 \
    --log "$out/logs/$id-stop-row.csv" "${pargs[@]}"
  run "$id" "deadman release" "$out/logs/$id-deadman.csv" \
    nice -n 10 "$bin" sim --input replay "$out/replays/$id-stop.csv" --no-realtime --no-telemetry \
    --log "$out/logs/$id-deadman.csv" "${pargs[@]}"
done
wait "$sigint_pid"

for id in "${ids[@]}"; do
  for e in replay-end stop-row deadman sigint; do
    log="$out/logs/$id-$e.csv"
    IFS=$'\t' read -r ending rc <"${log%.csv}.rc"
    printf '%s\t%s\t%s\t%s\t%s\t%s\t%s\n' "$id" "${label[$id]}" "${cut[$id]}" "$ending" "$log" \
      "${log%.csv}.out" "$rc" >>"$manifest"
  done
done

python3 "$py" report "$manifest" --out "$out/stop_figures.md"
