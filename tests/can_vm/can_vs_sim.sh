# Guest script of can_vm_can_vs_sim (tools/can-vm/run.sh): the heavy lift (650 kg) and the demo
# replay through the bus against `craneassist emulate`, compared with the same replays on the sim
# backend (docs/can.md, "CAN versus sim").
#   1. the shipped K70M mapping (20 ms valve commands, 0.01 deg encoders, feedback every 10 ms):
#      the pump energy within 5 % (the demo: 15 %, below); the direction errors are reported;
#   2. the same machine with 10 ms valve commands, 5 ms feedback and 0.0001 deg encoders (the
#      mapping rewritten here): the energy within 5 % (15 %) and the rms direction error of the
#      tip's displacement within 1 deg of the sim backend's (the largest errors are reported);
#   3. the crane scale and the power bound with 650 kg unannounced at 20 kW (below).
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
compare() {  # LABEL FILE PAYLOAD SIM_OUT MAPPING DIR_DEG ENERGY_PCT [emulator options]
  label=$1; file=$2; payload=$3; sim_out=$4; mapping=$5; dir=$6; energy=$7; shift 7
  for attempt in 1 2; do
    if replay_can "$file" "$payload" /tmp/can.out "$mapping" "$@" &&
       ./can_backend_check summary "$sim_out" /tmp/can.out "$energy" "$dir"; then
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
# The demo's energy within 15 %: a light load, so the cylinders' friction (docs/loads.md) is a
# large share of it, and over the bus the P feedback's corrections vary it from run to run (37.8
# to 43.1 kJ in ten runs, against 37.9 kJ on the sim backend).
compare "heavy lift: pump energy" heavy_lift.csv 650 /tmp/heavy_sim.out k70m_can.yaml -1 5
compare "demo: pump energy" demo.csv 0 /tmp/demo_sim.out k70m_can.yaml -1 15
echo "=== 2. 10 ms commands, 5 ms feedback, 0.0001 deg encoders"
compare "heavy lift, finer machine: energy or direction" heavy_lift.csv 650 /tmp/heavy_sim.out \
  /tmp/fine2.yaml 1 5 --feedback-period 0.005
compare "demo, finer machine: energy or direction" demo.csv 0 /tmp/demo_sim.out /tmp/fine2.yaml 1 \
  15 --feedback-period 0.005

# The crane scale over the bus (docs/loads.md): 650 kg in the emulated grapple, the controller
# told nothing, the prime mover at 20 kW so that power binds. The estimate from the mapping's
# chamber pressures (0.01 bar steps, the simulator's sensor noise), the peak pump power and the
# 95th percentile of the tip's direction error (from its displacement over 100 ms,
# can_backend_check p95), against the targets: 3 % of the rated 650 kg, 1.02 P_max, 2 deg.
# The K70M's load chart is left out here: this lift ends near 100 % of it, where the limiter
# (checked in part 4) would decide the figures. So is its hanging grapple (docs/sway.md): the
# scale's accuracy is measured on the load it was specified for, rigid at the tip (swinging, one
# of the shipped mapping's runs ended at 672.8 kg: docs/loads.md).
#   a. every resolution on the finer machine of part 2;
#   b. the shipped mapping (20 ms commands, 0.01 deg encoders), every resolution, and pinv-joint
#      told the load.
# The estimate and the peak power are checked; the direction is reported only: over the bus it
# is the bus's (told, on the shipped mapping, about 3 deg) and in the emulated VM it varies from
# run to run by a degree or two, told or not (docs/can.md, "The crane scale over the bus").
echo "=== 3. 650 kg unannounced over the bus at 20 kW"
sed -e 's/prime_mover_power: 35 kW/prime_mover_power: 20 kW/' -e '/^load_chart:/,/^ *rated_load:/d' \
  -e '/^grapple:/,/^ *damping:/d' k70m.yaml > /tmp/k70m_20kw.yaml
grep -q "prime_mover_power: 20 kW" /tmp/k70m_20kw.yaml || fail "the 20 kW config was not written"
grep -q "^load_chart:" /tmp/k70m_20kw.yaml && fail "the load chart is still in the 20 kW config"
grep -q "^grapple:" /tmp/k70m_20kw.yaml && fail "the grapple still hangs in the 20 kW config"
bus_run() {  # NAME CONFIG PAYLOAD REPLAY MAPPING FEEDBACK_S [replay options]: /tmp/bus_NAME.*
  name=$1; config=$2; payload=$3; replay=$4; mapping=$5; feedback=$6; shift 6
  ./craneassist emulate --can vcan0 --payload "$payload" --config "$config" --mapping "$mapping" \
    --feedback-period "$feedback" >/tmp/emu.log 2>&1 &
  emu=$!
  sleep 0.5
  ./craneassist replay "$replay" --config "$config" --backend can --can vcan0 --mapping "$mapping" \
    --log "/tmp/bus_$name.csv" --settle 1.5 --can-feedback-timeout 0.3 "$@" \
    >"/tmp/bus_$name.out" 2>&1 || fail "the bus run $name exited $?"
  kill "$emu"; wait "$emu"
  est=$(sed -n 's/.*load: [a-z]* \([0-9.]*\) kg.*/\1/p' "/tmp/bus_$name.out")
  peak=$(sed -n 's/.*peak power \([0-9.]*\) kW.*/\1/p' "/tmp/bus_$name.out")
  path=$(sed -n 's/.*tip: path \([0-9.]*\) m.*/\1/p' "/tmp/bus_$name.out")
  dir=$(./can_backend_check p95 "/tmp/bus_$name.csv")
  echo "$name over the bus: load ${est:-?} kg ($payload kg), peak power ${peak:-?} kW, tip path ${path:-?} m, direction error p95 $dir deg"
  awk -v e="${est:--1}" -v m="$payload" 'BEGIN { exit !(e >= m - 19.5 && e <= m + 19.5) }' ||
    { fail "$name: load ${est:-?} kg"; grep -E "load|error" "/tmp/bus_$name.out"; }
}
lift() {  # NAME MAPPING FEEDBACK_S RESOLUTION [replay options]
  name=$1; mapping=$2; feedback=$3; r=$4; shift 4
  bus_run "$name" /tmp/k70m_20kw.yaml 650 heavy_lift.csv "$mapping" "$feedback" --resolution "$r" "$@"
  awk -v p="${peak:-99}" 'BEGIN { exit !(p <= 20.4) }' || fail "$name: peak power ${peak:-?} kW"
}
for r in pinv-joint pinv-actuator min-flow min-ls-power; do
  lift "fine_$r" /tmp/fine2.yaml 0.005 "$r"
done
lift shipped_told k70m_can.yaml 0.01 pinv-joint --payload 650 --payload-known
for r in pinv-joint pinv-actuator min-flow min-ls-power; do
  lift "shipped_$r" k70m_can.yaml 0.01 "$r"
done

# 4. The rated capacity limiter over the bus: 1200 kg at the start pose (about 150 % of the
# K70M's chart there), the controller told nothing. Pushing out is refused (the tip moves less
# than 5 cm); pulling in stays free.
echo "=== 4. 1200 kg over the bus: out refused, in free"
printf 't,v_x,v_y,v_z\n0,0,0,0\n1,0.4,0,0\n4,0,0,0\n' > /tmp/out.csv
printf 't,v_x,v_y,v_z\n0,0,0,0\n1,-0.4,0,0\n4,0,0,0\n' > /tmp/in.csv
bus_run overload_out k70m.yaml 1200 /tmp/out.csv k70m_can.yaml 0.01
grep -q "OVERLOADED" /tmp/bus_overload_out.out || fail "overload_out: the limiter did not trip"
awk -v p="${path:-99}" 'BEGIN { exit !(p < 0.05) }' || fail "overload_out: the tip moved ${path:-?} m out"
bus_run overload_in k70m.yaml 1200 /tmp/in.csv k70m_can.yaml 0.01
awk -v p="${path:-0}" 'BEGIN { exit !(p > 0.8) }' || fail "overload_in: the tip moved only ${path:-?} m in"
exit $status
