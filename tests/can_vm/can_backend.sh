# Guest script of the can_vm_can_backend test (tools/can-vm/run.sh, busybox sh in the VM, vcan0
# up): the emulator and `craneassist replay --backend can` on vcan0, checked against the sim
# backend and from independent candump captures; then the fault cases; then the live loop
# (`craneassist sim --backend can`) against the live loop on the sim backend; then controller
# error frames on the bus and every way a run ends on the CAN backend (its end, --duration,
# SIGINT): the valves come down gradually, never from flow to block in one frame; then the
# J1939 address claim against a rival node and the valves' replies and DM1 (emulator hooks).
# The live runs leave DDS telemetry off (--no-telemetry): the one emulated CPU is busy enough.
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
# Until the emulator runs its loop (it prints its settings just before), then a little more: its
# start-up and first catch-up steps are CPU bursts that, under qemu's software emulation, can
# starve a control loop started at the same moment past its 80 ms watchdog.
wait_emulator() {
  for _ in $(seq 100); do
    grep -q "feedback every" "$1" 2>/dev/null && break
    sleep 0.1
  done
  sleep 0.5
}
start_emulator() {
  ./craneassist emulate --can vcan0 >/tmp/emu.log 2>&1 &
  emu=$!
  wait_emulator /tmp/emu.log
}
start_capture() {
  candump -L vcan0 >"$1" &
  cd_pid=$!
  sleep 0.2
}
stop_capture() { sleep 0.2; kill "$cd_pid"; wait "$cd_pid" 2>/dev/null; }

echo "=== 0. the project's SocketCAN transport classifies controller error frames on this kernel"
./transport_errors || fail "transport error-frame classification"

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
./can_backend_check compare /tmp/sim.csv /tmp/can.csv 0.05 pump || fail "tip paths or pump differ"
# The grapple's swing sensor over the bus (the emulator sends the simulator's swing on the
# mapping's grapple frame): the CAN run measures the swing as the sim run does.
grep -q "swing: peak" /tmp/can.out || fail "no swing measured over the bus"
grep "swing:" /tmp/sim.out /tmp/can.out
echo "--- the independent candump capture"
./can_backend_check traffic /tmp/cap1.log || fail "traffic"
echo "--- the backend's own candump log"
./can_backend_check traffic /tmp/backend.log || fail "backend log"
# --can-log marks the direction (candump -l -x): what craneassist sent T, what it received R.
grep -q ' T$' /tmp/backend.log && grep -q ' R$' /tmp/backend.log || fail "backend log: no T/R marks"

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
./can_backend_check wait-motion vcan0 10 || fail "the replay did not start moving"
sleep 0.2
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
# The control of the stop check below: a fault blocks at once, and the check must see that.
if ./can_backend_check stop /tmp/cap3.log 250; then fail "the stop check passed an abrupt block"; fi

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
grep heartbeat /tmp/emu.log
grep -q "heartbeat lost" /tmp/emu.log || fail "the emulator did not see the heartbeat stop"
./can_backend_check safe /tmp/cap4.log last-motion 130 || fail "safe state after the freeze"
echo "=== 5. the ISOBUS valve-group example mapping (every section an AVC valve, 1..4)"
./craneassist emulate --can vcan0 --mapping pvg32_isobus_example.yaml >/tmp/emu5.log 2>&1 &
emu=$!
wait_emulator /tmp/emu5.log
start_capture /tmp/cap5.log
./craneassist replay can_short.csv --backend can --can vcan0 --mapping pvg32_isobus_example.yaml \
  --log /tmp/can5.csv --settle 0.5 --can-feedback-timeout 0.3 >/tmp/f5.out 2>&1 || fail "replay with the ISOBUS mapping exited $?"
stop_capture
kill "$emu"; wait "$emu"
grep CAN /tmp/f5.out
./can_backend_check compare /tmp/sim.csv /tmp/can5.csv 0.05 || fail "tip paths differ (ISOBUS mapping)"
for v in 0CFE3180 0CFE3280 0CFE3380 0CFE3480; do
  grep -q " vcan0 $v#" /tmp/cap5.log || fail "no AVC frames $v in the capture"
done
echo "=== 6. the live loop (craneassist sim) on the CAN backend: the replay as a live operator"
./craneassist sim --no-telemetry --input replay can_short.csv --no-realtime --log /tmp/live_sim.csv \
  >/tmp/live_sim.out 2>&1 || fail "sim on the sim backend exited $?"
start_emulator
start_capture /tmp/cap6.log
./craneassist sim --no-telemetry --input replay can_short.csv --backend can --can vcan0 --log /tmp/live_can.csv \
  --can-feedback-timeout 0.3 >/tmp/live_can.out 2>&1 || fail "sim --backend can exited $?"
stop_capture
kill "$emu"; wait "$emu"
cat /tmp/live_can.out
grep -q "craneassist sim: replay input on .*, can backend" /tmp/live_can.out || fail "not on the can backend"
./can_backend_check compare /tmp/live_sim.csv /tmp/live_can.csv 0.05 || fail "live tip paths differ"
# The normal end: the backend's disable() blocks every section (the last commands are blocks).
./can_backend_check safe /tmp/cap6.log last-motion 100 || fail "not blocked at the end of the live run"
echo "=== 7. the live loop on CAN, the emulator dies: the run stops with the report, exit 3"
start_emulator
./craneassist sim --no-telemetry --input replay can_short.csv --backend can --can vcan0 --log /tmp/live_f7.csv \
  >/tmp/live_f7.out 2>&1 &
rp=$!
sleep 2
kill -9 "$emu"
wait "$rp"; rc=$?
cat /tmp/live_f7.out
[ "$rc" = 3 ] || fail "expected exit 3 after the fault, got $rc"
grep -q "CAN FAULT (feedback lost)" /tmp/live_f7.out || fail "no feedback-lost fault"
grep -q "the machine reported a fault: run stopped" /tmp/live_f7.out || fail "the run did not stop"
grep -q "ran [0-4]\.[0-9]* s of machine time" /tmp/live_f7.out || fail "the run went on after the fault"
echo "=== 8. controller error frames during a replay: bus-off, error-passive and a restart latch"
# cansend writes an error frame when the 8-digit id has CAN_ERR_FLAG (0x20000000): the class is
# in the id, the controller state in byte 1 (linux/can/error.h).
# One error frame during a replay; 1 when the run was not there to take it: a frozen-loop fault
# (an 80 ms stall of the loop thread) before the frame. Under qemu's software emulation a busy
# moment of the emulated CPUs does that now and then; that is the watchdog working, not the
# error-frame handling under test, so such an attempt is run again once.
error_frame_case() {
  frame=$1
  reason=$2
  start_emulator
  candump -L vcan0,0:0,#FFFFFFFF >/tmp/cap8.log &
  cd_pid=$!
  sleep 0.2
  ./craneassist replay can_short.csv --backend can --can vcan0 --no-log --settle 0 \
    --can-feedback-timeout 0.3 >/tmp/f8.out 2>&1 &
  rp=$!
  moving=0
  ./can_backend_check wait-motion vcan0 10 && moving=1
  sleep 0.3
  cansend vcan0 "$frame"
  wait "$rp"; rc=$?
  stop_capture
  kill "$emu" 2>/dev/null; wait "$emu"  # it may have stopped on the error frame itself
  grep CAN /tmp/f8.out
  if grep -q "CAN FAULT (control loop frozen)" /tmp/f8.out; then return 1; fi
  [ "$moving" = 1 ] || fail "$reason: the replay did not start moving"
  [ "$rc" = 3 ] || fail "$reason: expected exit 3 after the fault, got $rc"
  grep -q "CAN FAULT ($reason)" /tmp/f8.out || fail "$reason: no fault reported"
  ./can_backend_check safe /tmp/cap8.log error-frame 100 || fail "$reason: safe state"
  return 0
}
for c in "20000040#0000000000000000:bus-off" "20000004#0020000000000000:error-passive" \
         "20000100#0000000000000000:controller restarted"; do
  if ! error_frame_case "${c%%:*}" "${c#*:}"; then
    echo "the loop stalled before the error frame (a busy emulated CPU): once more"
    error_frame_case "${c%%:*}" "${c#*:}" || fail "${c#*:}: the loop stalled before the frame twice"
  fi
done

echo "=== 9. ACK and protocol errors are counted, the run goes on"
start_emulator
./craneassist replay can_short.csv --backend can --can vcan0 --log /tmp/can9.csv --settle 0.5 \
  --can-feedback-timeout 0.3 >/tmp/f9.out 2>&1 &
rp=$!
./can_backend_check wait-motion vcan0 10 || fail "the replay did not start moving"
for i in 1 2 3 4 5 6 7 8 9 10; do cansend vcan0 20000020#0000000000000000; done
for i in 1 2 3 4 5; do cansend vcan0 20000008#0000040000000000; done
wait "$rp"; rc=$?
kill "$emu"; wait "$emu"
grep CAN /tmp/f9.out
[ "$rc" = 0 ] || fail "ACK errors: expected exit 0, got $rc"
grep -q "bus errors 15," /tmp/f9.out || fail "ACK and protocol errors not counted"

echo "=== 10. a replay that ends with the crane moving: jerk-limited stop, then block"
start_emulator
start_capture /tmp/cap10.log
./craneassist replay can_ends_moving.csv --backend can --can vcan0 --no-log --settle 0 \
  --can-feedback-timeout 0.3 >/tmp/f10.out 2>&1; rc=$?
stop_capture
kill "$emu"; wait "$emu"
grep "CAN\|end of run\|stops:" /tmp/f10.out
[ "$rc" = 0 ] || fail "end of run: expected exit 0, got $rc"
grep -q "end of run: stopped in" /tmp/f10.out || fail "end of run: no stop reported"
# The valves go neutral only with the machine measured at rest (issue 27).
grep -Eq "end of run: .*at rest \(tip 0\.00[0-9] m/s\)" /tmp/f10.out ||
  fail "end of run: the valves went neutral on a moving crane"
./can_backend_check stop /tmp/cap10.log 250 || fail "end of run: valves not brought down gradually"

echo "=== 11. sim --duration ends while the crane moves"
start_emulator
start_capture /tmp/cap11.log
./craneassist sim --no-telemetry --input replay can_short.csv --duration 1.5 --backend can \
  --can vcan0 --can-feedback-timeout 0.3 >/tmp/f11.out 2>&1; rc=$?
stop_capture
kill "$emu"; wait "$emu"
cat /tmp/f11.out
[ "$rc" = 0 ] || fail "--duration: expected exit 0, got $rc"
grep -Eq "end of run: .*at rest \(tip 0\.00[0-9] m/s\)" /tmp/f11.out ||
  fail "--duration: the valves went neutral on a moving crane"
./can_backend_check stop /tmp/cap11.log 250 || fail "--duration: valves not brought down gradually"

echo "=== 12. SIGINT while the crane moves (the operator quits)"
start_emulator
start_capture /tmp/cap12.log
./craneassist sim --no-telemetry --input replay can_short.csv --backend can --can vcan0 \
  --can-feedback-timeout 0.3 >/tmp/f12.out 2>&1 &
rp=$!
./can_backend_check wait-motion vcan0 10 || fail "the run did not start moving"
sleep 0.8
kill -INT "$rp"
wait "$rp"; rc=$?
stop_capture
kill "$emu"; wait "$emu"
cat /tmp/f12.out
[ "$rc" = 0 ] || fail "SIGINT: expected exit 0, got $rc"
grep -q "ran [0-2]\.[0-9]* s of machine time" /tmp/f12.out || fail "SIGINT: the run did not end early"
grep -Eq "stop: .*at rest \(tip 0\.00[0-9] m/s\)" /tmp/f12.out ||
  fail "SIGINT: the valves went neutral on a moving crane"
./can_backend_check stop /tmp/cap12.log 250 || fail "SIGINT: valves not brought down gradually"
echo "=== 14. J1939 address claim: a node with a higher-priority NAME holds 0x80"
# j1939_rival (raw socket, not the project's codecs) answers craneassist's claim with its own.
start_emulator
start_capture /tmp/cap14.log
./j1939_rival vcan0 80 0000000000000001 30 >/tmp/rival14.log 2>&1 &
rv=$!
sleep 0.2
./craneassist replay can_short.csv --backend can --can vcan0 --no-log --settle 0 >/tmp/f14.out 2>&1; rc=$?
stop_capture
kill "$emu" "$rv"; wait "$emu"; wait "$rv"
cat /tmp/rival14.log /tmp/f14.out
[ "$rc" = 3 ] || fail "claim lost: expected exit 3, got $rc"
grep -q "CAN FAULT (address lost) at .*: cannot claim address 0x80: node with NAME 0x0000000000000001 has priority" /tmp/f14.out ||
  fail "claim lost: no cannot-claim fault reported"
./can_backend_check claim /tmp/cap14.log lost 0000000000000001 || fail "claim lost: capture"

echo "=== 15. a lower-priority contender gives way; the run proceeds until the lift valve fails"
./craneassist emulate --can vcan0 --test-valve-fault-at 2.5 --test-valve-fault-joint lift \
  >/tmp/emu15.log 2>&1 &
emu=$!
wait_emulator /tmp/emu15.log
start_capture /tmp/cap15.log
./j1939_rival vcan0 80 5000000000000001 30 >/tmp/rival15.log 2>&1 &
rv=$!
sleep 0.2
./craneassist replay can_short.csv --backend can --can vcan0 --no-log --settle 0 \
  --can-feedback-timeout 0.3 >/tmp/f15.out 2>&1; rc=$?
stop_capture
kill "$emu" "$rv"; wait "$emu"; wait "$rv"
cat /tmp/rival15.log /tmp/emu15.log; grep CAN /tmp/f15.out
[ "$rc" = 3 ] || fail "valve fault: expected exit 3, got $rc"
grep -q "CAN FAULT (valve fault) at .*: joint lift: valve 1 (0x20) reports a non-recoverable fault (limit status 6" /tmp/f15.out ||
  fail "valve fault: not reported"
./can_backend_check claim /tmp/cap15.log won 5000000000000001 || fail "claim won: capture"
./can_backend_check safe /tmp/cap15.log valve-fault 100 || fail "valve fault: safe state"

echo "=== 16. the valve replies stop (test hook at 2.5 s)"
./craneassist emulate --can vcan0 --test-reply-stop-at 2.5 >/tmp/emu16.log 2>&1 &
emu=$!
wait_emulator /tmp/emu16.log
start_capture /tmp/cap16.log
./craneassist replay can_short.csv --backend can --can vcan0 --no-log --settle 0 \
  --can-feedback-timeout 0.3 >/tmp/f16.out 2>&1; rc=$?
stop_capture
kill "$emu"; wait "$emu"
grep CAN /tmp/f16.out
[ "$rc" = 3 ] || fail "reply silence: expected exit 3, got $rc"
grep -q "CAN FAULT (valve reply lost) at .*: joint .*: no valve reply for [0-9]* ms" /tmp/f16.out ||
  fail "reply silence: not reported"
# The fault is due 300 ms after the last reply: every section blocked within 100 ms of that.
./can_backend_check safe /tmp/cap16.log last-reply 400 || fail "reply silence: safe state"

echo "=== 17. DM1 from the valve group with an active DTC (test hook at 2.5 s)"
./craneassist emulate --can vcan0 --test-dm1-fault-at 2.5 >/tmp/emu17.log 2>&1 &
emu=$!
wait_emulator /tmp/emu17.log
start_capture /tmp/cap17.log
./craneassist replay can_short.csv --backend can --can vcan0 --no-log --settle 0 \
  --can-feedback-timeout 0.3 >/tmp/f17.out 2>&1; rc=$?
stop_capture
kill "$emu"; wait "$emu"
grep CAN /tmp/f17.out
[ "$rc" = 3 ] || fail "DM1: expected exit 3, got $rc"
grep -q "CAN FAULT (DM1 fault) at .*: DM1 from 0x20: SPN 1234 FMI 5 (red stop lamp)" /tmp/f17.out ||
  fail "DM1: not reported"
./can_backend_check safe /tmp/cap17.log dm1-fault 100 || fail "DM1: safe state"

echo "=== 13. feedback lost while the wall clock steps back (timed on CLOCK_MONOTONIC)"
# The clock goes back years the moment the emulator dies: freshness timed on the wall clock
# would see the last position frame in the future and the fault would wait for the run's end.
start_emulator
./craneassist replay can_short.csv --backend can --can vcan0 --no-log --settle 0 >/tmp/f13.out 2>&1 &
rp=$!
./can_backend_check wait-motion vcan0 10 || fail "the replay did not start moving"
kill -9 "$emu"
date -s "2020-01-01 00:00:00" >/dev/null
wait "$rp"; rc=$?
grep CAN /tmp/f13.out
[ "$rc" = 3 ] || fail "clock step: expected exit 3 after the fault, got $rc"
grep -q "CAN FAULT (feedback lost) at [0-3]\.[0-9]* s" /tmp/f13.out ||
  fail "clock step: lost feedback not found within the run"
exit "$status"
