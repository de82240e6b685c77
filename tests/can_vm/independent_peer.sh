# Guest script of the CTest can_vm_independent_peer (tools/can-vm/run.sh --python, busybox sh in the
# VM, vcan0 up): `craneassist replay --backend can` against valve_peer.py, a valve group and its
# sensors written in Python from the DBC alone (python-can and canmatrix, nothing of craneassist's
# codecs), so a codec error on craneassist's side can no longer pass by being mirrored in the
# emulator. docs/can.md, "Tested against an independent peer".
#   (a) a normal replay: exit 0, the peer's checks pass, every section blocked at the end;
#   (b) craneassist killed with SIGKILL while the crane moves: the peer puts the sections in
#       fail-safe on silence within its timeout;
#   (c) the backend's --can-log of (a) decoded through the DBC by canmatrix;
#   (d) the control: frames a valve must not accept, put on the bus with cansend, must fail the
#       peer's checks (so that (a) passing means something).
set -u
status=0
fail() { echo "FAIL: $*"; status=1; }
now() { cut -d' ' -f1 /proc/uptime; }
case_start=$(now)
took() {  # the time since the previous case began
  t=$(now)
  echo "--- took $(awk -v a="$case_start" -v b="$t" 'BEGIN { printf "%.1f", b - a }') s"
  case_start=$t
}
wait_file() {  # wait_file FILE SECONDS
  tries=0
  until [ -e "$1" ]; do
    tries=$((tries + 1)); [ "$tries" -lt $(($2 * 20)) ] || return 1
    sleep 0.05
  done
}
start_peer() {  # start_peer OUTPUT [OPTION...]: the peer on vcan0, returns once it sends feedback
  out="$1"
  shift
  rm -f /tmp/peer.ready /tmp/peer.moving
  t0=$(now)
  # --cycle-tolerance 0.2: the mean command period within 20 % of the DBC's 20 ms. The project's
  # candump check asserts 10 %, beside the lighter C++ emulator; with this Python peer taking
  # about 40 % of an emulated CPU, and other builds on the host, craneassist's loop is late more
  # often, and its send schedule counts from the last send (docs/can.md: measured up to 22.3 ms).
  python3 valve_peer.py /tmp/k70m.dbc --channel vcan0 --ready-file /tmp/peer.ready \
    --motion-file /tmp/peer.moving --cycle-tolerance 0.2 "$@" >"$out" 2>&1 &
  peer=$!
  wait_file /tmp/peer.ready 60 || { cat "$out"; echo "FAIL: the peer did not start"; exit 1; }
  echo "peer sending feedback $(awk -v a="$t0" -v b="$(now)" 'BEGIN { printf "%.1f", b - a }') s after its start"
}

echo "=== the DBC, written by craneassist from its embedded K70M mapping"
./craneassist can dbc -o /tmp/k70m.dbc || { echo "FAIL: craneassist can dbc"; exit 1; }
grep -c '^BO_ ' /tmp/k70m.dbc | sed 's/^/messages in the DBC: /'

took
echo "=== (a) replay against the independent peer"
start_peer /tmp/peer_a.out
t0=$(now)
./craneassist replay can_short.csv --backend can --can vcan0 --no-log --settle 0.5 \
  --can-feedback-timeout 0.3 --can-log /tmp/backend.log >/tmp/replay_a.out 2>&1; rc=$?
t1=$(now)
wait "$peer"; prc=$?
cat /tmp/replay_a.out /tmp/peer_a.out
echo "replay ran $(awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.1f", b - a }') s, exit $rc; peer exit $prc"
[ "$rc" = 0 ] || fail "(a) replay --backend can exited $rc"
[ "$prc" = 0 ] || fail "(a) the peer's checks failed (exit $prc)"
grep -q "every section's last command: block" /tmp/peer_a.out || fail "(a) not every section blocked at the end"

took
echo "=== (b) craneassist killed while the crane moves: fail-safe on silence"
start_peer /tmp/peer_b.out --expect-silence
./craneassist replay can_short.csv --backend can --can vcan0 --no-log --settle 0 \
  --can-feedback-timeout 0.3 >/tmp/replay_b.out 2>&1 &
rp=$!
if wait_file /tmp/peer.moving 30; then
  sleep 0.5
  kill -9 "$rp"
  echo "craneassist killed at $(now) s (uptime)"
else
  fail "(b) the peer never saw motion"
  kill -9 "$rp"
fi
wait "$rp" 2>/dev/null
wait "$peer"; prc=$?
cat /tmp/peer_b.out
[ "$prc" = 0 ] || fail "(b) the peer's checks failed (exit $prc)"
grep -q "fail-safe on silence: " /tmp/peer_b.out || fail "(b) no fail-safe on silence reported"

took
echo "=== (c) the backend's log of (a) decoded through the DBC"
python3 decode_can_log.py /tmp/k70m.dbc /tmp/backend.log --moving --ends-blocked || fail "(c) decode"

took
echo "=== (d) control: wrong frames must fail the peer's checks"
start_peer /tmp/peer_d.out --exit-after-silence 0.5
# AVC byte 2 0xFD: resolution mode 1, reserved bits 1; byte 3 0x31: extend, fail-safe block.
for f in 0CFE3080#00FD310000FFFFFF 0CFE3180#00FD340000FFFFFF 0CFE3280#7DFD71007DFFFFFF \
         0CFE3080#7DFD3100FAFFFFFF 0CFE3180#7D0131007DFFFFFF 0CFE3280#FBFD3100FFFFFFFF \
         210#E803 18FF0080#050100FFFFFFFFFF 18FF0080#070100FFFFFFFFFF 123#00; do
  cansend vcan0 "$f"
done
wait "$peer"; prc=$?
grep "VIOLATION\|FAIL" /tmp/peer_d.out
[ "$prc" = 1 ] || fail "(d) the peer passed wrong frames (exit $prc)"
for what in "ValveState extend with flow 0 %" "ValveState 4 (?), not block/extend/retract" \
            "FailSafeMode 1, expected 0" "extended flow 100 % vs 8-bit 50 %" "reserved bits not all 1" \
            "PortFlowCommand raw 251 above 250" "1000 mA outside" "AliveCounter 5 -> 7" \
            "frames foreign to the DBC: 123"; do
  grep -qF "$what" /tmp/peer_d.out || fail "(d) the peer did not report: $what"
done
took
exit $status
