# Guest script of the can_vm_socketcan_smoke test (run by tools/can-vm/run.sh with busybox sh in
# the VM, from /tests, vcan0 and vcan1 up). candump records both buses while the smoke test sends;
# then the test checks the capture holds exactly the frames it sent.
set -u
capture=/tmp/candump.log
sent=/tmp/sent.log
: >"$sent"

candump -L any >"$capture" &
candump_pid=$!
# Wait until candump's raw socket is registered with the CAN core (not a fixed sleep).
tries=0
until grep -q raw /proc/net/can/rcvlist_all 2>/dev/null; do
  tries=$((tries + 1))
  [ "$tries" -lt 100 ] || { echo "candump did not start"; exit 1; }
  sleep 0.05
done

status=0
CAN_VM_SENT_LOG="$sent" ./socketcan_smoke --gtest_filter='SocketCan.*' || status=1

sleep 0.2  # let candump read the last frames, then stop it (SIGTERM: it flushes and exits)
kill "$candump_pid"
wait "$candump_pid" || true
echo "candump -L any: $(wc -l <"$capture") lines, the last three:"
tail -n 3 "$capture"

CAN_VM_SENT_LOG="$sent" CAN_VM_CANDUMP_LOG="$capture" \
  ./socketcan_smoke --gtest_filter='CandumpParser.*:CandumpCapture.*' || status=1
exit "$status"
