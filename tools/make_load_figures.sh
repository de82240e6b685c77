#!/usr/bin/env bash
# Regenerates the figures of docs/loads.md from fresh runs of the simulator (build first:
# cmake --build build): the crane scale on a work cycle, on a log slipping out of the grapple,
# and the rated capacity limiter on a 1200 kg load pushed out (and, without a figure, 700 kg
# pushed out, which trips the limiter on the way). Prints each run's load lines of the summary and
# keeps them in docs/data/loads_summary.txt. Needs python3-matplotlib.
set -euo pipefail
cd "$(dirname "$0")/.."
bin=build/app/craneassist
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
summary=docs/data/loads_summary.txt

# The overload run: 1200 kg in the grapple (the controller is not told), the stick pushed
# straight out at 0.4 m/s for 4 s.
mkdir "$out/replays"
cat >"$out/replays/push_out.csv" <<'EOF'
t,v_x,v_y,v_z
0,0,0,0
1,0.4,0,0
5,0,0,0
EOF

{
  echo "# The summary's load lines of the runs of tools/make_load_figures.sh (docs/loads.md)."
  echo "# push_out.csv: t,v_x,v_y,v_z rows 0,0,0,0 / 1,0.4,0,0 / 5,0,0,0 (the script writes it)."
} >"$summary"

# run NAME TITLE REPLAY [OPTION...]: one replay with its log, its figure docs/img/loads_NAME.png
# (none when TITLE is empty) and the summary's load lines (printed and appended to the summary
# file).
run() {
  local name=$1 title=$2 replay=$3
  shift 3
  local shown="build/app/craneassist replay ${replay#"$out/replays/"}${*:+ $*}"
  $bin replay "$replay" "$@" --log "$out/$name.csv" >"$out/$name.txt"
  {
    echo "$ $shown"
    grep -E '^  (load: |load moment: |LOAD ABOVE A PORT RELIEF)' "$out/$name.txt" || true
  } | tee -a "$summary"
  if [[ -n $title ]]; then
    tools/plot_loads.py "$out/$name.csv" "docs/img/loads_$name.png" --title "$title" >/dev/null
  fi
}

run work_cycle "work_cycle.csv: a 450 kg log nobody announces" examples/replays/work_cycle.csv
run slip "work_cycle_slip.csv: the log slips out of the grapple at 7.5 s" \
  examples/replays/work_cycle_slip.csv
run overload "1200 kg pushed straight out at 0.4 m/s (the controller is not told)" \
  "$out/replays/push_out.csv" --payload 1200
run push_out_700 "" "$out/replays/push_out.csv" --payload 700
echo "figures written to docs/img/loads_*.png, the load lines to $summary"
