#!/bin/sh
# craneassist's ROS 2 topics (docs/ros.md) read by a Cyclone DDS reader built from ROS 2's own
# message definitions (cyclone_ros2_reader.c), as a ROS 2 node would see them: a replay with a
# constant tip command, `--ros2` under the namespace /crane1.
# Usage: ros2_messages.sh CRANEASSIST CYCLONE_ROS2_READER DOMAIN
set -eu
. "$(dirname "$0")/../cli/test_lib.sh"
bin=$1
reader=$2
domain=$3

# The joints as the URDF names them (the movable ones, in order): what JointState must carry.
"$bin" urdf > "$work/crane.urdf"
joints=$(grep '<joint ' "$work/crane.urdf" | grep -v 'type="fixed"' |
  sed 's/.*name="\([^"]*\)".*/\1/' | paste -sd, -)
[ -n "$joints" ] || fail "no joints in the URDF"

# The command in the crane frame (x forward, y up, z lateral) and in base_link (the K70M's
# crane_from_base swaps y and z): what the TwistStamped must carry.
printf 't,v_x,v_y,v_z\n0.1,0.3,0.2,-0.1\n2.5,0,0,0\n' > "$work/replay.csv"
command_base=0.3,-0.1,0.2
cat > "$work/telemetry.yaml" <<YAML
format: craneassist-telemetry/1
topics:
  joints: {reliability: reliable}   # the last sample compared with joint_states' must arrive
ros2:
  namespace: /crane1
YAML

"$reader" "$domain" 40 /crane1 "$joints" "$command_base" > "$work/reader.out" 2> "$work/reader.err" &
bg_pid=$!
wait_ready reader.out reader.err
"$bin" replay "$work/replay.csv" --realtime --settle 3 --no-log --ros2 --domain "$domain" \
  --telemetry-config "$work/telemetry.yaml" > "$work/replay.out" 2>&1 ||
  { cat "$work/replay.out"; fail "replay failed"; }
rc=0
wait "$bg_pid" || rc=$?
bg_pid=
cat "$work/reader.out" "$work/reader.err"
grep "telemetry" "$work/replay.out"
[ "$rc" = 0 ] || fail "cyclone ros2 reader: exit $rc"
has replay.out "ROS 2 topics /crane1/joint_states"
has reader.out " 0 failed checks"
has reader.out "last positions = last craneassist q: yes"
echo "joints: $joints; command in base_link: $command_base"
echo "ros2 OK"
