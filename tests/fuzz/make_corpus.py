#!/usr/bin/env python3
"""Writes the seed corpora of the fuzz harnesses (tests/fuzz/corpus/<harness>/, docs/fuzzing.md)
from the repository's example files and a few hand-made edge cases. Run from anywhere; it
replaces the seed files it makes and leaves any other file in the corpus folders alone.

    tests/fuzz/make_corpus.py
"""
import glob
import os
import struct

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
CORPUS = os.path.join(ROOT, "tests", "fuzz", "corpus")


def write(harness, name, data):
    folder = os.path.join(CORPUS, harness)
    os.makedirs(folder, exist_ok=True)
    if isinstance(data, str):
        data = data.encode()
    with open(os.path.join(folder, name), "wb") as f:
        f.write(data)


def read(path):
    with open(os.path.join(ROOT, path), "rb") as f:
        return f.read()


def files(pattern):
    return sorted(glob.glob(os.path.join(ROOT, pattern)))


# --- input files --------------------------------------------------------------------------------
for path in (files("examples/replays/*.csv") + files("examples/replays/suite/*.csv") +
             files("examples/replays/loading/*.csv")) + [
        os.path.join(ROOT, "tests/data", n)
        for n in ("bad_replay.csv", "can_short.csv", "remote_short.csv")]:
    write("fuzz_replay", os.path.basename(path), open(path, "rb").read())
write("fuzz_replay", "edge_crlf_bom_stop.csv",
      "\ufeff# comment\r\nt,v_x,v_y,v_z,stop\r\n0,0.1,0,0,0\r\n0.5,0,0,0,1\r\n1e9,0,-0.2,5,0\r\n")
write("fuzz_replay", "edge_stop_wait_load.csv",
      "t,v_x,v_y,v_z,stop,wait,load_kg\n0,0.1,0,0,0,0,\n0.5,0,0,0,1,1,300\n1,0,0,0,0,1,\n")
write("fuzz_replay", "edge_numbers.csv",
      "t , v_x , v_y , v_z\n\n0,-0,+1e-308,4.9999999999999999\n1e-300,0x1p-3,5,-5\n")

for path in files("examples/paths/*.csv") + [os.path.join(ROOT, "tests/data/bad_path.csv")]:
    write("fuzz_prescribed_path", os.path.basename(path), open(path, "rb").read())
write("fuzz_prescribed_path", "edge_two_points.csv", "t,x,y,z\n0,1,2,3\n0.001,-100,100,0\n")

write("fuzz_joint_trajectory", "two_joints.csv",
      "# planned by hand\nt,q_1,q_2,qdot_1,qdot_2,qddot_1,qddot_2\n"
      "0,0,0.5,0,0,0,0\n0.5,0.1,0.45,0.2,-0.1,0,0\n1,0.2,0.4,0,0,0,0\n")
write("fuzz_joint_trajectory", "six_joints.csv",
      "t," + ",".join(f"q_{i}" for i in range(1, 7)) + "," +
      ",".join(f"qdot_{i}" for i in range(1, 7)) + "," +
      ",".join(f"qddot_{i}" for i in range(1, 7)) + "\n0" + ",0" * 18 + "\n2" + ",1" * 18 + "\n")
write("fuzz_joint_trajectory", "bad_trajectory.csv", read("tests/data/bad_trajectory.csv"))

# Tool paths of the crane on wheels (craneassist research follow).
write("fuzz_tool_path", "mobile_s_curve.csv", read("examples/paths/mobile_s_curve.csv"))
write("fuzz_tool_path", "edge_two_points.csv", "x,y\n0,0\n0.01,0\n")
write("fuzz_tool_path", "edge_crlf_bom_turn.csv",
      "\ufeff# a U-turn\r\nx , y\r\n0,0\r\n5,0\r\n5,0.5\r\n-1e4,0.5\r\n")
write("fuzz_tool_path", "bad_header.csv", "t,x,y\n0,0,0\n1,1,1\n")

# Posture tables of the planner (the first byte picks how the rest changes a real table).
write("fuzz_posture_table", "as_built.bin", b"\x01")
write("fuzz_posture_table", "cut.bin", b"\x02\x40\x00")
write("fuzz_posture_table", "patched.bin", b"\x01\x30\x00\x07\x2c\x00\x00\x60\x01\xff")
write("fuzz_posture_table", "replaced.bin",
      b"\x00" + struct.pack("<diiiiii", 0.1, 3, -1, 4, 3, 2, 3) + struct.pack("<ii", 3, -1) * 2)

# Joint poses (--initial, suite poses) and suite manifests.
for name, text in (("folded.txt", "lift=0 deg, tilt=-125 deg, extension=0.2 m"),
                   ("units.txt", "slew=0.5 rad,lift=10deg , extension = 150 mm"),
                   ("one_joint.txt", "tilt=-1.2 rad"),
                   ("out_of_range.txt", "extension=9 m"),
                   ("twice.txt", "lift=1 deg, lift=2 deg")):
    write("fuzz_joint_pose", name, text)
write("fuzz_suite_manifest", "suite.yaml", read("examples/replays/suite.yaml"))
write("fuzz_suite_manifest", "loading.yaml", read("examples/replays/loading.yaml"))
write("fuzz_suite_manifest", "variants.yaml", read("examples/machines/variants.yaml"))
write("fuzz_suite_manifest", "baseline_fields.yaml",
      "format: craneassist-suite/1\nruns:\n  - replay: demo.csv\n    scaling: flow\n"
      "    sway_damping: false\n    wait_swing: 3 deg\n"
      "    targets: {residual_swing: 2 deg, cycle_time: 40 s, timed_out_waits: 0,"
      " overload_cycles: 0}\n")
write("fuzz_suite_manifest", "long_name.yaml",  # a name longer than NAME_MAX: once a crash
      "format: craneassist-suite/1\nruns:\n  - replay: " + "a" * 300 + ".csv\n")
write("fuzz_suite_manifest", "payload_targets.yaml",
      "format: craneassist-suite/1\nposes:\n  low: lift=5 deg\ntargets:\n  stall_events: 0\n"
      "runs:\n  - replay: heavy_lift.csv\n    poses: [default, low]\n    payload: 650 kg\n"
      "    targets: {lateral_speed: 0.05 m/s}\n")

# The web page's stick state.
write("fuzz_web_pad", "pad.json", '{"type":"pad","axes":[0.5,-1,0,1,0,0],"deadman":true}')
write("fuzz_web_pad", "short.json", '{"type":"pad","axes":[],"deadman":false}')
write("fuzz_web_pad", "unicode.json", '{"type":"p\\u0061d","axes":[1e-3, -0.0],"deadman":true,"x":[{}]}')

# The shared reader: a selector byte (flags of the format) and a file of its columns.
write("fuzz_csv_reader", "full.csv", b"\x00t,a,b,f\n0,1,2,0\n0.5,-1,1e300,1\n")
write("fuzz_csv_reader", "optional.csv", b"\x06# c\nt,a\n0,4.5\n0.0005,1\n")
write("fuzz_csv_reader", "step_limit.csv", b"\x19t,a,b\n0,1,2\n0.0001,1,2\n")
write("fuzz_csv_reader", "rows.csv", b"\x08t,a,b,f\n0,0,0,0\n1,0,0,0\n2,0,0,0\n3,0,0,0\n")

# --- YAML files ---------------------------------------------------------------------------------
for path in files("config/cranes/*.yaml") + [os.path.join(ROOT, "tests/data/bad_config.yaml")]:
    write("fuzz_crane_config", os.path.basename(path), open(path, "rb").read())
for path in files("config/joysticks/*.yaml") + [os.path.join(ROOT, "tests/data/bad_joystick.yaml")]:
    write("fuzz_joystick_config", os.path.basename(path), open(path, "rb").read())
for path in files("config/machines/*.yaml"):
    write("fuzz_base_config", os.path.basename(path), open(path, "rb").read())
for path in files("config/telemetry/*.yaml"):
    write("fuzz_telemetry_config", os.path.basename(path), open(path, "rb").read())
write("fuzz_telemetry_config", "commands.yaml",
      "domain: 7\nrates: {status: 5 Hz}\ncommands:\n  enabled: true\n  security:\n"
      "    ca: ca.pem\n")
write("fuzz_telemetry_config", "type_propagation.yaml",
      "format: craneassist-telemetry/1\ntype_propagation: {type_object: false, "
      "type_information: true}\n")
for path in files("config/can/*.yaml"):
    write("fuzz_can_mapping", os.path.basename(path), open(path, "rb").read())
for path in files("config/can/*.dbc"):
    write("fuzz_dbc", os.path.basename(path), open(path, "rb").read())
write("fuzz_dbc", "vendor.dbc",
      'VERSION "1"\n\nNS_ :\n\tCM_\n\tBA_\n\nBS_: 250000 : 0,0\n\nBU_: ECU1 Valves\n'
      'VAL_TABLE_ OnOff 1 "on" 0 "off" ;\n'
      'BO_ 2566848513 BoomAngles: 8 ECU1\n'
      ' SG_ Boom1Angle : 0|16@1- (0.01,-10) [-190|170] "deg" Valves,ECU1\n'
      ' SG_ ArmAngle : 39|16@0+ (0.1,0) [0|3600] "deg"  Valves\n'
      'BO_ 1280 Muxed: 8 ECU1\n'
      ' SG_ Selector M : 0|8@1+ (1,0) [0|3] "" Valves\n'
      ' SG_ PressureA m0 : 8|16@1+ (0.1,0) [0|500] "bar" Valves\n'
      ' SG_ Temperature : 24|32@1- (1,0) [0|0] "degC" Valves\n'
      'BO_TX_BU_ 1280 : ECU1,Valves;\n'
      'CM_ BO_ 2566848513 "two\nlines, with a \\" quote";\n'
      'BA_DEF_ BO_  "GenMsgCycleTime" INT 0 10000;\n'
      'BA_ "GenMsgCycleTime" BO_ 2566848513 10;\n'
      'BA_ "VFrameFormat" BO_ 2566848513 3;\n'
      'VAL_ 1280 Selector 0 "a" 1 "b" ;\n'
      'SIG_VALTYPE_ 1280 Temperature : 1;\n')
for name, text in (("flow_block.yaml", "[[[[{a: [b, {c: d}]}]]]]\n"),
                   ("anchors.yaml", "a: &x [1, 2]\nb: *x\n? [complex]\n: key\n"),
                   ("tags.yaml", "!!binary aGVsbG8=\n--- !custom {x: 1}\n")):
    for harness in ("fuzz_crane_config", "fuzz_joystick_config", "fuzz_telemetry_config",
                    "fuzz_can_mapping", "fuzz_base_config"):
        write(harness, name, text)

# --- CAN ----------------------------------------------------------------------------------------
write("fuzz_candump", "lines.log",
      "(1700000000.123456) vcan0 18FE3080#0102030405060708\n"
      "(0.000000) can0 123#\n"
      "(1.000001) vcan1 7FF#DEADBEEF\r\n"
      "  (12.5) vcan0 1FFFFFFF#00  \n")
write("fuzz_candump", "unsupported.log",
      "(1.000000) vcan0 123#R\n(1.000000) vcan0 123##1112233\n(1.000000) vcan0 20000080#00\n"
      "(-1.000000) vcan0 123#00\n(1.000000) vcan0 800#00\n(1.000000) vcan0 123#0\n")
write("fuzz_candump", "format.bin",
      b"\xff" + struct.pack("<I", 0x18FE3080) + b"\x01\x08" + bytes(range(8)) +
      struct.pack("<q", 1700000000123456) + b"\x60" + b"vcan0")


def frame(can_id, data, extended=True, flags=1):
    raw = can_id | (0x80000000 if extended else 0)
    return struct.pack("<IB", raw, len(data)) + bytes(data).ljust(8, b"\xff") + bytes([flags])


k70m = b"".join(
    [frame(0x18FF1021 + j, [0x10, 0x27]) for j in range(4)] +
    [frame(0x301 + j, [0x88, 0x13, 0x10, 0x27], extended=False) for j in range(4)] +
    [frame(0x310, [0x00, 0x50, 0xa0, 0x0f], extended=False),
     frame(0x18FF0080, [1, 1, 0, 0xff, 0xff, 0xff, 0xff, 0xff], flags=3),
     frame(0x0CFE3080, [125, 0xfd, 0x31, 0x40, 0x7d, 0xff, 0xff, 0xff]),
     frame(0x0CFE2180, [150, 100, 0x10, 0x27, 0x20, 0x4e, 10, 0xff]),
     frame(0x0CFE1180, [150, 100, 0x31, 0xff, 0xff, 0xff, 0xff, 0xff]),
     frame(0x210, [0x00, 0x80], extended=False)])
write("fuzz_can_frames", "k70m_traffic.bin", k70m)
# J1939 network management and the valve group's replies (k70m_can.yaml): a contending claim of
# 0x80, requests, Estimated Flow from 0x20 (limit status 6 in one), the driver's status, DM1
# (quiet, a DTC, short) and a multi-packet DM1's TP.CM BAM and TP.DT packets.
write("fuzz_can_frames", "j1939_network.bin", b"".join([
    frame(0x18EEFF80, [1, 0, 0, 0, 0, 0, 0, 0]),
    frame(0x18EEFF80, [0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0x7f]),
    frame(0x18EAFF21, [0x00, 0xee, 0x00]),
    frame(0x18EA8021, [0x00, 0xee, 0x00, 0xff, 0xff, 0xff, 0xff, 0xff]),
    frame(0x0CFE1020, [150, 100, 0xf1, 0x1f, 0xff, 0xff, 0xff, 0xff]),
    frame(0x0CFE1120, [125, 125, 0xf0, 0xdf, 0xff, 0xff, 0xff, 0xff]),
    frame(0x211, [0], extended=False),
    frame(0x18FECA20, [0x00, 0xff, 0, 0, 0, 0, 0xff, 0xff]),
    frame(0x18FECA20, [0x10, 0xff, 0xd2, 0x04, 0x05, 0x01, 0xff, 0xff], flags=3),
    frame(0x18FECA20, [0x10, 0xff]),
    frame(0x1CECFF20, [32, 14, 0, 2, 0xff, 0xca, 0xfe, 0x00]),
    frame(0x1CEBFF20, [1, 0x10, 0xff, 0xd2, 0x04, 0x05, 0x01, 0xd3])]))
write("fuzz_can_frames", "pgn_pages.bin",
      frame(0x1BFE3080, [0] * 8) + frame(0x03FF1021, [0] * 8) + frame(0x18EAFF00, [0, 0xee, 0]))

for name, spec in (("intel16.bin", bytes([1, 0x21, 0x10, 0xff, 0x18, 0, 16, 0, 0, 1])),
                   ("motorola.bin", bytes([1, 0x23, 0x10, 0xff, 0x18, 7, 16, 1, 1, 1])),
                   ("len64.bin", bytes([0, 0x10, 0x01, 0, 0, 0, 64, 0, 1, 0]))):
    write("fuzz_signal_map", name, spec + bytes(range(40)))


# --- DDS samples (CDR, little endian encapsulation) ----------------------------------------------
class Cdr:
    def __init__(self):
        self.body = b""

    def align(self, n):
        self.body += b"\0" * ((-len(self.body)) % n)

    def put(self, fmt, value):
        size = struct.calcsize("<" + fmt)
        self.align(size)
        self.body += struct.pack("<" + fmt, value)

    def string(self, s):
        data = s.encode() + b"\0"
        self.put("I", len(data))
        self.body += data

    def doubles(self, values):
        for v in values:
            self.put("d", v)

    def seq_doubles(self, values):
        self.put("I", len(values))
        self.doubles(values)

    def bytes(self):
        return b"\x00\x01\x00\x00" + self.body  # CDR_LE, options 0


def header(c, cycle):
    c.put("Q", cycle)
    c.put("d", cycle * 0.01)
    c.put("q", 123456789)


c = Cdr()
header(c, 42)
for s in ("K70M", "sim", "running", "", "power", "none", "replay"):
    c.string(s)
c.put("B", 1)
c.doubles([0.8, 0.5, 0.002, 1e-4, 2e-4])
c.put("Q", 3)
write("fuzz_dds_samples", "status.bin", b"\x00" + c.bytes())

c = Cdr()
header(c, 43)
names = ["slew", "lift", "tilt", "extension"]
c.put("I", len(names))
for n in names:
    c.string(n)
c.put("I", 4)
c.body += bytes([0, 0, 0, 1])
for values in ([0.1, 0.2, -2.1, 0.5],) * 8:
    c.seq_doubles(values)
c.doubles([5.0, 2.0, 0.1, 0.1, -0.2, 0.0])
write("fuzz_dds_samples", "joints.bin", b"\x01" + c.bytes())

c = Cdr()
header(c, 44)
c.string("load-sensing")
c.doubles([6.6e-4, 1.5e7, 9.9e3, 3.6e4, 2e-3, 3.5e4, 6e-4, 1e4])
c.string("none")
write("fuzz_dds_samples", "hydraulics.bin", b"\x02" + c.bytes())

c = Cdr()
header(c, 45)
c.string("keyboard")
c.put("B", 1)
c.doubles([0.3, 0, 0, 0.25, 0, 0, 0.8, 1.2, 0.5, 0.1, 4.0, -1.0, 1.0])
write("fuzz_dds_samples", "command_path.bin", b"\x03" + c.bytes())

c = Cdr()
c.put("Q", 7)
c.string("operator")
c.doubles([0.2, -0.1, 0.0])
c.put("B", 1)
write("fuzz_dds_samples", "operator_command.bin", b"\x04" + c.bytes())
write("fuzz_dds_samples", "operator_command_be.bin",
      b"\x04\x00\x00\x00\x00" + struct.pack(">Q", 8) + struct.pack(">I", 2) + b"x\0" +
      b"\0" * 6 + struct.pack(">ddd", 0.1, float("nan"), 0.0) + b"\x01")

c = Cdr()
header(c, 1)
write("fuzz_dds_samples", "header.bin", b"\x05" + c.bytes())

c = Cdr()
header(c, 46)
c.doubles([12.5, -3.0, 0.4, 0.3, 0.05, 0.33, 0.06])
c.doubles([2.6e-4, 2.7e-4, 2.6e-4, 2.7e-4, 1.06e-3, 1.05e-3])
c.put("B", 1)
write("fuzz_dds_samples", "base.bin", b"\x06" + c.bytes())
