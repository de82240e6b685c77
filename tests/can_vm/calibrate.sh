# Guest script of the can_vm_calibrate test (tools/can-vm/run.sh, busybox sh in the VM, vcan0
# up): `craneassist calibrate --backend can` against the emulator on vcan0 (the lift, a short
# level set), the same sweep on the sim backend, and the fitted tables compared; the traffic
# checked from an independent candump capture. Then the ways a sweep on a machine ends early:
# SIGINT (the spools ramp to neutral, then block; exit 3) and the emulator killed (the backend's
# fault, exit 3 with its reason).
set -u
status=0
fail() { echo "FAIL: $*"; status=1; }

start_emulator() {
  ./craneassist emulate --can vcan0 >/tmp/emu.log 2>&1 &
  emu=$!
  sleep 0.5
}
start_capture() {
  candump -L vcan0 >"$1" &
  cd_pid=$!
  sleep 0.2
}
stop_capture() { sleep 0.2; kill "$cd_pid"; wait "$cd_pid" 2>/dev/null; }

# The fitted tables may differ by this share of the top speed: the emulator runs the same
# physics, the bus adds 0.01 deg encoder steps and 10 ms feedback (measured on a quiet host: at
# most 0.5 %). A level whose window did not settle is measured again by the sweep itself.
tolerance=0.05

# calibrate_can N: the lift's sweep over CAN against a fresh emulator, captured.
calibrate_can() {
  start_emulator
  start_capture /tmp/cap1.log
  # A longer feedback timeout, as for the replay comparison of can_backend.sh: a loaded host can
  # stall the emulated CPU for tens of ms.
  ./craneassist calibrate --backend can --can vcan0 --section lift --levels 0.3,0.6,1.0 \
    --can-feedback-timeout 0.3 --out /tmp/can.yaml --log /tmp/can.csv >/tmp/can.out 2>&1 ||
    fail "calibrate --backend can exited $? (try $1)"
  stop_capture
  kill "$emu"; wait "$emu"
  cat /tmp/can.out /tmp/can.yaml /tmp/emu.log
  grep -q "on the machine (can backend)" /tmp/can.out || fail "not on the can backend"
}

echo "=== 1. the lift's sweep on the sim backend and on the CAN backend (emulator on vcan0)"
./craneassist calibrate --section lift --levels 0.3,0.6,1.0 --out /tmp/sim.yaml \
  --log /tmp/sim.csv >/tmp/sim.out 2>&1 || fail "calibrate on the sim backend exited $?"
cat /tmp/sim.out
calibrate_can 1
if ! ./can_backend_check tables /tmp/sim.yaml /tmp/can.yaml "$tolerance"; then
  # On a host loaded by other work, TCG can starve the emulator's 1 kHz simulation: its crane
  # then falls behind real time and catches up, running faster than real time over a whole
  # measuring window (+14 % once, with the host's load average at 5). That is the test rig's
  # clock, not the sweep; one more sweep, and both are reported.
  echo "--- the tables differ; the sweep once more"
  calibrate_can 2
  ./can_backend_check tables /tmp/sim.yaml /tmp/can.yaml "$tolerance" || fail "the tables differ"
fi
./can_backend_check traffic /tmp/cap1.log || fail "traffic"

echo "=== 2. SIGINT during the sweep: the spools ramp to neutral, every section blocks, exit 3"
start_emulator
start_capture /tmp/cap2.log
./craneassist calibrate --backend can --can vcan0 --section lift --levels 1.0 \
  --can-feedback-timeout 0.3 --out /tmp/int.yaml --log /tmp/int.csv >/tmp/int.out 2>&1 &
cp=$!
./can_backend_check wait-motion vcan0 10 || fail "the sweep did not start moving"
sleep 1.5
kill -INT "$cp"
wait "$cp"; rc=$?
stop_capture
kill "$emu"; wait "$emu"
cat /tmp/int.out
[ "$rc" = 3 ] || fail "SIGINT: expected exit 3, got $rc"
grep -q "calibration stopped: stop requested during the sweep of lift" /tmp/int.out || fail "SIGINT: no stop reported"
[ ! -e /tmp/int.yaml ] || fail "SIGINT: tables written for an unfinished sweep"
# Ramped, not thrown to neutral: the flow the emulator measures falls over tens of ms (a block
# at once: 7-10 ms, docs/can.md), and the last command of every section is block.
./can_backend_check stop /tmp/cap2.log 50 || fail "SIGINT: the flow was not brought down gradually"
./can_backend_check safe /tmp/cap2.log last-motion 100 || fail "SIGINT: not blocked at the end"

echo "=== 3. the emulator dies during the sweep: feedback lost, exit 3 with the reason"
start_emulator
./craneassist calibrate --backend can --can vcan0 --section lift --levels 1.0 \
  --out /tmp/f3.yaml --log /tmp/f3.csv >/tmp/f3.out 2>&1 &
cp=$!
./can_backend_check wait-motion vcan0 10 || fail "the sweep did not start moving"
sleep 1
kill -9 "$emu"
wait "$cp"; rc=$?
cat /tmp/f3.out
[ "$rc" = 3 ] || fail "lost feedback: expected exit 3, got $rc"
grep -q "CAN FAULT (feedback lost)" /tmp/f3.out || fail "lost feedback: no fault reported"
grep -q "calibration stopped: machine fault: joint .*: no position frame" /tmp/f3.out ||
  fail "lost feedback: the reason is not given"
exit "$status"
