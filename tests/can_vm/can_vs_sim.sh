# Guest script of can_vm_can_vs_sim (tools/can-vm/run.sh): the heavy lift (650 kg) and the demo
# replay through the bus against `craneassist emulate`, compared with the same replays on the sim
# backend (docs/can.md, "CAN versus sim").
#   1. the shipped K70M mapping (20 ms valve commands, 0.01 deg encoders, feedback every 10 ms):
#      the pump energy within 5 %; the direction errors are reported;
#   2. the same machine with 10 ms valve commands, 5 ms feedback and 0.0001 deg encoders (the
#      mapping rewritten here): the energy within 5 % and the rms direction error of the tip's
#      displacement within 1 deg of the sim backend's (the largest errors are reported).
set -u
status=0
fail() { echo "FAIL: $*"; status=1; }

# The finer machine: 32-bit positions at 1e-4 deg (1e-3 mm), every cycle 10 ms. A position signal
# spans two lines of the shipped file: from `position: {id: 0x18FF10..` to its closing brace.
sed -e 's/cycle: 20 ms/cycle: 10 ms/g' k70m_can.yaml > /tmp/fine.yaml
awk '
  /position: \{id: 0x18FF10/ { pos = 1 }
  pos && /length: 16/ { sub(/length: 16/, "length: 32") }
  pos && /scale: 0.01,/ { sub(/scale: 0.01,/, "scale: 0.0001,") }
  pos && /scale: 0.1,/ { sub(/scale: 0.1,/, "scale: 0.001,") }
  { print }
  /\}/ { pos = 0 }' /tmp/fine.yaml > /tmp/fine2.yaml
grep -c "length: 32" /tmp/fine2.yaml | grep -q '^4$' || fail "the finer mapping was not written (4 positions of 32 bits expected)"
grep -q "cycle: 20 ms" /tmp/fine2.yaml && fail "the finer mapping still has 20 ms cycles"

replay_sim() {  # FILE PAYLOAD OUT
  ./craneassist replay "$1" --payload "$2" --no-log --settle 0.5 >"$3" 2>&1 || fail "sim replay of $1 exited $?"
}
replay_can() {  # FILE PAYLOAD OUT MAPPING [emulator options]; fails when the replay does
  file=$1; payload=$2; out=$3; mapping=$4; shift 4
  ./craneassist emulate --can vcan0 --payload "$payload" --mapping "$mapping" "$@" >/tmp/emu.log 2>&1 &
  emu=$!
  sleep 0.5
  ./craneassist replay "$file" --payload "$payload" --backend can --can vcan0 --mapping "$mapping" \
    --no-log --settle 0.5 --can-feedback-timeout 0.3 >"$out" 2>&1
  rc=$?
  kill "$emu"; wait "$emu"
  grep -o "fell behind.*" /tmp/emu.log
  [ "$rc" = 0 ] || { grep -E "FAULT|error" "$out"; echo "the CAN replay of $file exited $rc"; }
  return "$rc"
}
# One comparison, run again once when it fails: a stalled emulated CPU (a busy host) sets a
# single cycle's error or a lost frame, and both runs are reported.
compare() {  # LABEL FILE PAYLOAD SIM_OUT MAPPING DIR_DEG [emulator options]
  label=$1; file=$2; payload=$3; sim_out=$4; mapping=$5; dir=$6; shift 6
  for attempt in 1 2; do
    if replay_can "$file" "$payload" /tmp/can.out "$mapping" "$@" &&
       ./can_backend_check summary "$sim_out" /tmp/can.out 5 "$dir"; then
      return 0
    fi
    echo "($label: attempt $attempt failed)"
  done
  fail "$label"
}

echo "=== the sim backend"
replay_sim heavy_lift.csv 650 /tmp/heavy_sim.out
replay_sim demo.csv 0 /tmp/demo_sim.out
echo "=== 1. the shipped mapping"
compare "heavy lift: pump energy" heavy_lift.csv 650 /tmp/heavy_sim.out k70m_can.yaml -1
compare "demo: pump energy" demo.csv 0 /tmp/demo_sim.out k70m_can.yaml -1
echo "=== 2. 10 ms commands, 5 ms feedback, 0.0001 deg encoders"
compare "heavy lift, finer machine: energy or direction" heavy_lift.csv 650 /tmp/heavy_sim.out \
  /tmp/fine2.yaml 1 --feedback-period 0.005
compare "demo, finer machine: energy or direction" demo.csv 0 /tmp/demo_sim.out /tmp/fine2.yaml 1 \
  --feedback-period 0.005
exit $status
