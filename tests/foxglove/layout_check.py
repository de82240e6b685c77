#!/usr/bin/env python3
"""The shipped Foxglove layout (examples/foxglove/craneassist-layout.json) names only channels
and fields craneassist publishes: every message path /craneassist/<group>.<field> is a property
of that group's JSON Schema (`craneassist fields --schema GROUP`), every other topic is one of the
cdr channels, and the 3-D panel takes the URDF from /robot_description. A user script of the
layout (userNodes: the viewer's TypeScript scripts, here the operator's units) reads only
craneassist channels and fields, and a path on its /studio_script/ output names a field of its
Output type.

    layout_check.py CRANEASSIST LAYOUT.json
"""
import json
import re
import subprocess
import sys

craneassist, layout_path = sys.argv[1:3]
layout = json.load(open(layout_path))
cdr = {"/robot_description", "/joint_states", "/tf", "/craneassist/tip_velocity/command",
       "/craneassist/tip_velocity/reference"}
failures = 0
schemas = {}


def fail(why):
    global failures
    failures += 1
    print("FAIL", why)


def walk(node):
    if isinstance(node, dict):
        for key, value in node.items():
            if key in ("value", "topic") and isinstance(value, str) and value.startswith("/"):
                yield value
            else:
                yield from walk(value)
    elif isinstance(node, list):
        for item in node:
            yield from walk(item)


def group_field(path):
    """Checks /craneassist/<group>.<field>...; None when the path is not of that form."""
    m = re.fullmatch(r"/craneassist/(\w+)\.(\w+)(.*)", path)
    if not m:
        return None
    group, field = m.group(1), m.group(2)
    if group not in schemas:
        out = subprocess.run([craneassist, "fields", "--schema", group], capture_output=True,
                             text=True)
        schemas[group] = json.loads(out.stdout) if out.returncode == 0 else None
    if schemas[group] is None:
        fail(f"{path}: no channel /craneassist/{group}")
    elif field not in schemas[group]["properties"]:
        fail(f"{path}: /craneassist/{group} has no field {field}")
    else:
        print(f"ok   {path}")
    return True


# The user scripts: their input channels, the fields they read of each message, their output.
script_fields = {}  # output topic -> its Output type's fields
for node in layout.get("userNodes", {}).values():
    code = node["sourceCode"]
    inputs = re.findall(r'"(/[^"]+)"', re.search(r"export const inputs = \[([^\]]*)\]", code).group(1))
    output = re.search(r'export const output = "([^"]+)"', code).group(1)
    if not output.startswith("/studio_script/"):
        fail(f"user script {node['name']}: output {output} outside /studio_script/")
    message = re.search(r"const (\w+) = event\.message;", code)
    read = set(re.findall(rf"\b{message.group(1)}\.(\w+)", code)) if message else set()
    if len(inputs) != 1 or not read:
        fail(f"user script {node['name']}: expected one input and the fields it reads")
    for field in sorted(read):
        group_field(f"{inputs[0]}.{field}")
    script_fields[output] = set(re.findall(r"^\s+(\w+): number;", code, re.M))
    print(f"ok   user script {node['name']}: {inputs} -> {output} {sorted(script_fields[output])}")

paths = list(walk(layout["configById"]))
for path in paths:
    script = next((o for o in script_fields if path.startswith(o + ".")), None)
    if script:
        field = re.match(r"\.(\w+)", path[len(script):]).group(1)
        if field in script_fields[script]:
            print(f"ok   {path}")
        else:
            fail(f"{path}: the user script's Output has no field {field}")
    elif group_field(path):
        pass
    elif path in cdr:
        print(f"ok   {path}")
    else:
        fail(f"{path}: not a craneassist channel")
urdf = [c for c in walk(layout["configById"]) if c == "/robot_description"]
if not urdf:
    fail("the 3-D panel does not take the URDF from /robot_description")
panels = set(layout["configById"])
used = set(re.findall(r'"([\w]+![\w]+)"', json.dumps(layout["layout"])))
if used != panels:
    fail(f"the layout tree and the panels differ: {sorted(used ^ panels)}")
print(f"{len(paths)} paths, {len(panels)} panels")
print("layout OK" if failures == 0 else f"{failures} FAILED")
sys.exit(1 if failures else 0)
