#!/usr/bin/env python3
"""The RIHS01 type hashes of ROS 2 messages (Iron and later), computed from their .msg files the
way rosidl computes them (ros2/rosidl, branch jazzy, rosidl_generator_type_description:
serialize_field_type, serialize_individual_type_description, extract_full_type_description,
calculate_type_hash), and checked against the values published for them. ROS 2 puts
`typehash=<hash>;` into each endpoint's USER_DATA; craneassist announces the hashes of
app/dds/src/ros2_writers.hpp, which this checks too (docs/ros.md).

The description hashed: {"type_description": {"type_name": "pkg/msg/Name", "fields": [...]},
"referenced_type_descriptions": [every type reachable from it, once, sorted by name]}, each field
{"name", "type": {"type_id", "capacity", "string_capacity", "nested_type_name"}} in the .msg's
order (rosidl's default_value key dropped), as json.dumps writes it with separators ', ' and
': ', unsorted keys, ASCII; the hash is "RIHS01_" + the SHA-256 of that text. Type ids are those
of type_description_interfaces/msg/FieldType.msg, after rosidl's .msg-to-IDL mapping (msg char is
uint8, byte is octet); T[N] adds 48, T[<=N] 96, T[] 144.

Usage: ros2_type_hash.py MSGDEFS_DIR[:DIR...] [--constants ros2_writers.hpp] PKG/NAME...
Exit 1 when a computed hash differs from its published value or from craneassist's constant.
Standard library only.
"""
import argparse
import hashlib
import json
import pathlib
import re
import sys

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
import ros2_msg_to_idl  # noqa: E402  the same .msg reading as the interop reader's IDL

IDS = {
    "int8": 2, "uint8": 3, "char": 3, "int16": 4, "uint16": 5, "int32": 6, "uint32": 7,
    "int64": 8, "uint64": 9, "float32": 10, "float64": 11, "bool": 15, "byte": 16,
    "string": 17, "wstring": 18,
}
NESTED, BOUNDED_STRING, BOUNDED_WSTRING = 1, 21, 22
ARRAY, BOUNDED_SEQUENCE, UNBOUNDED_SEQUENCE = 48, 96, 144

# Published hashes (Jazzy; the .msg definitions are the same from Iron to Rolling):
#  JointState: `ros2 topic info -v` of Jazzy, docs/../references-2026-11 (several sources agree),
#    and rosidl_generator_c's joint_state__description.c (hpmicro/hpm_sdk, micro-ROS);
#  Header, Time: the same file's referenced types; Time also RosLibRust/roslibrust
#    roslibrust_codegen/assets/AddTwoInts.json;
#  TwistStamped, Twist, Vector3: twist_stamped__description.c (hpmicro/hpm_sdk);
#  ParticipantEntitiesInfo: eclipse-zenoh/zenoh-plugin-ros2dds src/ros_discovery.rs
#    ("in Iron and Jazzy"); Gid and NodeEntitiesInfo: a rosidl-generated
#    participant_entities_info__description.c.
PUBLISHED = {
    "sensor_msgs/msg/JointState":
        "RIHS01_a13ee3a330e346c9d87b5aa18d24e11690752bd33a0350f11c5882bc9179260e",
    "std_msgs/msg/Header":
        "RIHS01_f49fb3ae2cf070f793645ff749683ac6b06203e41c891e17701b1cb597ce6a01",
    "builtin_interfaces/msg/Time":
        "RIHS01_b106235e25a4c5ed35098aa0a61a3ee9c9b18d197f398b0e4206cea9acf9c197",
    "geometry_msgs/msg/TwistStamped":
        "RIHS01_5f0fcd4f81d5d06ad9b4c4c63e3ea51b82d6ae4d0558f1d475229b1121db6f64",
    "geometry_msgs/msg/Twist":
        "RIHS01_9c45bf16fe0983d80e3cfe750d6835843d265a9a6c46bd2e609fcddde6fb8d2a",
    "geometry_msgs/msg/Vector3":
        "RIHS01_cc12fe83e4c02719f1ce8070bfd14aecd40f75a96696a67a2a1f37f7dbb0765d",
    "rmw_dds_common/msg/ParticipantEntitiesInfo":
        "RIHS01_91a0593bacdcc50ea9bdcf849a938b128412cc1ea821245c663bcd26f83c295e",
    "rmw_dds_common/msg/NodeEntitiesInfo":
        "RIHS01_8ffef65ee2d088c63b1e8fcd31e800ba9fc8dbe0ee15ca60d1676de5218087a7",
    "rmw_dds_common/msg/Gid":
        "RIHS01_ab6f21cfbb0a6dbb837161e1110c2051a2850ed9f9c53944d7115d9bcebedf71",
}
# craneassist's constants (app/dds/src/ros2_writers.hpp) and the types they are of.
CONSTANTS = {
    "kJointStateTypeHash": "sensor_msgs/msg/JointState",
    "kTwistStampedTypeHash": "geometry_msgs/msg/TwistStamped",
    "kParticipantEntitiesInfoTypeHash": "rmw_dds_common/msg/ParticipantEntitiesInfo",
}


def field_type(pkg, type_text):
    """(type_id, capacity, string_capacity, nested_type_name) of a .msg field type."""
    m = re.fullmatch(r"([\w/]+)(<=(\d+))?(\[(<=)?(\d*)\])?", type_text)
    if not m:
        sys.exit(f"cannot read type {type_text!r}")
    base, string_bound, array, bounded, size = (m.group(1), m.group(3), m.group(4), m.group(5),
                                                 m.group(6))
    nested, string_capacity = "", 0
    if string_bound and base in ("string", "wstring"):
        type_id = BOUNDED_STRING if base == "string" else BOUNDED_WSTRING
        string_capacity = int(string_bound)
    elif base in IDS:
        type_id = IDS[base]
    else:
        target, _ = ros2_msg_to_idl.resolve(pkg, base)
        type_id, nested = NESTED, f"{target[0]}/msg/{target[1]}"
    capacity = 0
    if array is not None:
        if size and not bounded:
            type_id, capacity = type_id + ARRAY, int(size)
        elif bounded:
            type_id, capacity = type_id + BOUNDED_SEQUENCE, int(size)
        else:
            type_id += UNBOUNDED_SEQUENCE
    return type_id, capacity, string_capacity, nested


def individual(msgdefs, full_name):
    pkg, _, name = full_name.split("/")
    fields = []
    for type_text, field_name in ros2_msg_to_idl.fields(msgdefs, pkg, name):
        type_id, capacity, string_capacity, nested = field_type(pkg, type_text)
        fields.append({"name": field_name, "type": {
            "type_id": type_id, "capacity": capacity, "string_capacity": string_capacity,
            "nested_type_name": nested}})
    if not fields:  # rosidl's placeholder for an empty message
        fields.append({"name": "structure_needs_at_least_one_member", "type": {
            "type_id": IDS["uint8"], "capacity": 0, "string_capacity": 0,
            "nested_type_name": ""}})
    return {"type_name": full_name, "fields": fields}


def type_hash(msgdefs, full_name):
    top = individual(msgdefs, full_name)
    referenced, pending = {}, [f["type"]["nested_type_name"] for f in top["fields"]]
    while pending:
        name = pending.pop()
        if not name or name in referenced:
            continue
        referenced[name] = individual(msgdefs, name)
        pending += [f["type"]["nested_type_name"] for f in referenced[name]["fields"]]
    description = {"type_description": top,
                   "referenced_type_descriptions": [referenced[n] for n in sorted(referenced)]}
    text = json.dumps(description, ensure_ascii=True, separators=(", ", ": "), sort_keys=False)
    return "RIHS01_" + hashlib.sha256(text.encode("utf-8")).hexdigest()


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("msgdefs", help="directories of <pkg>/msg/<Name>.msg, ':'-separated")
    ap.add_argument("--constants", help="craneassist's ros2_writers.hpp")
    ap.add_argument("types", nargs="+", help="PKG/NAME")
    args = ap.parse_args()
    msgdefs = [pathlib.Path(d) for d in args.msgdefs.split(":")]
    failed, computed = 0, {}
    names = [f"{t.split('/')[0]}/msg/{t.split('/')[1]}" for t in args.types]
    for name in names + [n for n in PUBLISHED if n not in names]:
        pkg = name.split("/")[0]
        if not any((d / pkg).is_dir() for d in msgdefs):
            continue  # a referenced type of a package not given
        computed[name] = type_hash(msgdefs, name)
        published = PUBLISHED.get(name)
        verdict = ("no published value" if published is None else
                   "= published" if published == computed[name] else f"!= published {published}")
        failed += published is not None and published != computed[name]
        print(f"{name} {computed[name]} {verdict}")
    if args.constants:
        text = pathlib.Path(args.constants).read_text()
        for constant, name in CONSTANTS.items():
            m = re.search(constant + r'\s*=\s*"(RIHS01_[0-9a-f]{64})"', text)
            ok = m is not None and m.group(1) == computed.get(name)
            failed += not ok
            print(f"craneassist {constant} {m.group(1) if m else 'missing'} "
                  f"{'= computed' if ok else '!= computed'} ({name})")
    print(f"{failed} mismatches")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
