#!/bin/sh
# What a Fast DDS 2.9 dynamic-type reader builds from craneassist's discovery data, per
# `type_propagation` (docs/telemetry.md, "Nested types and dynamic-type tools").
# Usage: type_discovery.sh CASE CRANEASSIST FASTDDS_TYPE_DISCOVERY REPLAY DOMAIN
#   type_object: the default settings: the type object in discovery; Fast DDS 2.x sends the
#     top-level type only, so the reader's types lack their nested `header` (the known limit)
#   type_information: TYPE_INFORMATION and the TypeLookup service: the types come whole
set -eu
. "$(dirname "$0")/../cli/test_lib.sh"
case_name=$1
bin=$2
discovery=$3
replay=$4
domain=$5

case $case_name in
type_object) printf 'format: craneassist-telemetry/1\n' > "$work/telemetry.yaml" ;;
type_information)
  printf 'format: craneassist-telemetry/1\ntype_propagation: {type_object: false, type_information: true}\n' \
    > "$work/telemetry.yaml" ;;
*) fail "unknown case $case_name" ;;
esac

"$discovery" "$domain" 20 > "$work/types.out" 2>&1 &
bg_pid=$!
wait_ready types.out types.out
"$bin" replay "$replay" --realtime --settle 1 --no-log --telemetry-config "$work/telemetry.yaml" \
  --domain "$domain" > "$work/replay.out" 2>&1 || { cat "$work/replay.out"; fail "replay failed"; }
wait "$bg_pid" || true
bg_pid=
cat "$work/types.out"
[ "$(grep -c "^type_[a-z]* craneassist/" "$work/types.out")" = 4 ] || fail "not 4 topics' types"
if [ "$case_name" = type_object ]; then
  # Fast DDS 2.9's limit: `header` (the nested Header struct) is missing from every type.
  has types.out "craneassist/status: craneassist::msg::Status, 14 members: active_limit backend crane deadman input_source"
  grep -q " header" "$work/types.out" && fail "header found: the limit is gone, update docs/telemetry.md"
else
  has types.out "craneassist/status: craneassist::msg::Status, 15 members: active_limit backend crane deadman header input_source"
  has types.out "craneassist/joints: craneassist::msg::JointState, 12 members: cylinder_pos_m cylinder_vel_m_s header"
  [ "$(grep -c " header " "$work/types.out")" = 4 ] || fail "header not in every type"
fi
echo "$case_name OK"
