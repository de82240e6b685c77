# Guest script of the can_vm_can_backend test (tools/can-vm/run.sh, busybox sh in the VM, vcan0
# up): the emulator and `craneassist replay --backend can` on vcan0, checked against the sim
# backend and from independent candump captures; then the fault cases.
set -u
status=0
fail() { echo "FAIL: $*"; status=1; }

wait_candump() {
  tries=0
  until grep -q raw /proc/net/can/rcvlist_all 2>/dev/null; do
    tries=$((tries + 1)); [ "$tries" -lt 100 ] || { echo "candump did not start"; exit 1; }
    sleep 0.05
  done
}
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

echo "=== 1. the same replay on the sim backend and on the CAN backend (emulator on vcan0)"
./craneassist replay can_short.csv --log /tmp/sim.csv --settle 0.5 >/tmp/sim.out 2>&1 || fail "sim replay"
start_emulator
start_capture /tmp/cap1.log
# A longer feedback timeout here: this case compares paths, and a loaded host can stall the
# emulated CPU for tens of ms (the fault cases below keep the default 50 ms).
./craneassist replay can_short.csv --backend can --can vcan0 --log /tmp/can.csv --settle 0.5 \
  --can-feedback-timeout 0.3 --can-log /tmp/backend.log >/tmp/can.out 2>&1 || fail "replay --backend can exited $?"
stop_capture
kill "$emu"; wait "$emu"
cat /tmp/can.out /tmp/emu.log
./can_backend_check compare /tmp/sim.csv /tmp/can.csv 0.05 || fail "tip paths differ"
echo "--- the independent candump capture"
./can_backend_check traffic /tmp/cap1.log || fail "traffic"
echo "--- the backend's own candump log"
./can_backend_check traffic /tmp/backend.log || fail "backend log"

echo "=== 2. the emulator dies: feedback stops"
start_emulator
start_capture /tmp/cap2.log
./craneassist replay can_short.csv --backend can --can vcan0 --no-log --settle 0 >/tmp/f2.out 2>&1 &
rp=$!
sleep 2
kill -9 "$emu"
wait "$rp"; rc=$?
stop_capture
grep CAN /tmp/f2.out
[ "$rc" = 3 ] || fail "expected exit 3 after the fault, got $rc"
grep -q "CAN FAULT (feedback lost)" /tmp/f2.out || fail "no feedback-lost fault"
./can_backend_check safe /tmp/cap2.log last-feedback 100 || fail "safe state after lost feedback"

echo "=== 3. garbage frames (ignored, counted), then a wrong dlc on the lift encoder"
start_emulator
start_capture /tmp/cap3.log
./craneassist replay can_short.csv --backend can --can vcan0 --no-log --settle 0 \
  --can-feedback-timeout 0.3 >/tmp/f3.out 2>&1 &
rp=$!
sleep 1
cangen vcan0 -I 555 -L r -D r -g 1 -n 100
cangen vcan0 -e -I 1ABCDEF0 -L r -D r -g 1 -n 100
cansend vcan0 18FF1022#01
wait "$rp"; rc=$?
stop_capture
kill "$emu"; wait "$emu"
grep CAN /tmp/f3.out
[ "$rc" = 3 ] || fail "expected exit 3 after the fault, got $rc"
grep -q "CAN FAULT (bad feedback frame)" /tmp/f3.out || fail "no bad-frame fault"
grep -q "unknown 2[0-9][0-9]," /tmp/f3.out || fail "garbage frames not counted"
./can_backend_check safe /tmp/cap3.log bad-frame 100 || fail "safe state after a wrong dlc"

echo "=== 4. the control loop freezes (test hook: 0.5 s at t = 1 s)"
start_emulator
start_capture /tmp/cap4.log
./craneassist replay can_short.csv --backend can --can vcan0 --no-log --settle 0 \
  --can-feedback-timeout 0.3 --test-freeze-at 1.0 --test-freeze-for 0.5 >/tmp/f4.out 2>&1; rc=$?
stop_capture
kill "$emu"; wait "$emu"
grep CAN /tmp/f4.out
[ "$rc" = 3 ] || fail "expected exit 3 after the fault, got $rc"
grep -q "CAN FAULT (control loop frozen)" /tmp/f4.out || fail "no frozen-loop fault"
./can_backend_check safe /tmp/cap4.log last-motion 130 || fail "safe state after the freeze"
exit "$status"
