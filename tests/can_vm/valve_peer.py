#!/usr/bin/python3
"""An independent machine on the CAN bus: a valve group and its sensors, simulated from a DBC.

craneassist's own emulator (`craneassist emulate`) shares craneassist's C++ codecs, so a codec
error on both sides would pass the VM tests. This peer shares nothing with craneassist: it reads
only the DBC that `craneassist can dbc` writes, decodes and encodes every frame with canmatrix and
talks to the bus with python-can (Debian's python3-canmatrix 0.9.5 and python3-can 4.1.0).

What it does, on a SocketCAN interface (vcan0 by default):
  - decodes craneassist's valve commands into one spool per section: ISO 11783-7 Auxiliary Valve
    Commands (PortFlowCommand %, ValveState, FailSafeMode, PortFlowCommandExtended), and signal
    outputs such as `extension_valve_command` in mA (spool = value / full scale of the signal);
  - integrates a kinematic model of each joint (joint rate from the spool through the valve's
    dead zone, times a maximum rate per joint; the K70M's values, see JOINTS below) and sends
    every position, pressure, pump and swing-sensor message of the DBC every --period (10 ms)
    through canmatrix's encoder (the swing sensor reads 0: the peer's grapple hangs still);
  - puts a section in fail-safe (spool 0) when its commands stop for --command-timeout, and every
    section when craneassist's heartbeat stops advancing for its timeout (read from the DBC's
    comment on the heartbeat message, else 100 ms), as a valve's own supervision would.

What it checks, and prints with figures at the end (exit status 1 when a check failed):
  - every command as a real valve would see it: the DBC's dlc; flow 0..100 %; valve state block,
    extend or retract only; block <=> flow 0; fail-safe mode the expected one (--fail-safe, the
    mapping's; the DBC does not carry it) and constant; resolution mode 0 or 1, the extended
    16-bit flow within one 8-bit step (0.4 %) of the 8-bit one (0xFFFF in mode 0); reserved bits
    (those no DBC signal covers) sent as 1; a signal output within the DBC's [min, max];
  - the period of every command message and of the heartbeat from the kernel's receive
    timestamps: mean, standard deviation and largest gap against the DBC's GenMsgCycleTime (the
    mean within --cycle-tolerance of it);
  - the heartbeat: AliveCounter +1 per message (no skip, no repeat), State enabled whenever a
    command asks for flow, never fault;
  - fail-safe on silence: without --expect-silence no section may go silent while it moves, and
    every section's last command must be block (the normal end of a run); with --expect-silence
    (craneassist killed) at least one section must have been moving when the commands stopped,
    and every moving section must reach fail-safe within the timeout plus --tolerance of its last
    command (the measured times are printed);
  - every valve section of the DBC was commanded, and no frame on the bus was foreign to the DBC;
  - its own feedback period (it must keep up for craneassist not to fault on stale feedback).

It ends --exit-after-silence seconds after craneassist's last frame, at --max-time, or on SIGTERM
or SIGINT, and prints the summary.

Usage:
  valve_peer.py DBC [--channel vcan0] [--period 0.01] [--command-timeout 0.1]
                [--heartbeat-timeout S] [--fail-safe block|float] [--expect-silence]
                [--tolerance 0.05] [--cycle-tolerance 0.1] [--exit-after-silence 1.0]
                [--start-timeout 60] [--max-time 300] [--ready-file F] [--motion-file F]

canmatrix 0.9.5 quirks, handled here: Frame.encode() takes raw values (not physical ones, whatever
its docstring says), so values are scaled and rounded here; CanMatrix.decode() returns {} for
11-bit frames in a J1939 DBC, so frames are indexed by (identifier, extended) and decoded with
Frame.decode().

Debian 12: apt install python3-can python3-canmatrix. Run it with /usr/bin/python3.
"""
import argparse
import logging
import math
import os
import re
import signal
import statistics
import sys
import time
import warnings

warnings.filterwarnings("ignore", category=SyntaxWarning)  # canmatrix 0.9.5's own code
logging.getLogger("canmatrix").setLevel(logging.ERROR)
import can  # noqa: E402
import canmatrix.formats  # noqa: E402

# The joints, from config/cranes/k70m.yaml (hard-coded on purpose: the peer reads nothing of the
# project but the DBC). Per joint: start position, joint range and maximum joint rate in SI (rad,
# m), the sign of joint motion for an extending cylinder, the section's full flow (L/min) for the
# pump frame, and constant cylinder pressures (bar, piston and rod side) to report.
#   start: simulation.initial (0 deg, 20 deg, -70 deg, 1.0 m).
#   range: joints[].min/max.
#   rate:  cylinder max_speed / |dc/dq| at the start pose: slew 0.10 m/s / 0.11459 m (rack and
#          pinion arm); lift 0.15 m/s / 0.438 m/rad (triangle linkage l1 0.44 m, l2 1.42 m,
#          offset 1.01 rad, at 20 deg); tilt 0.15 m/s / 0.308 m/rad (the quintic c3(q3) at
#          -70 deg, where the cylinder shortens as q3 grows: sign -1); extension 0.40 m/s / 0.5.
#   flow:  max_speed times the piston area (the extension's differential spool: A_A - A_B).
JOINTS = {
    "slew": dict(start=0.0, lo=-math.pi, hi=math.pi, rate=0.10 / 0.11459, sign=1, flow=62.3,
                 pressure=(20.0, 20.0)),
    "lift": dict(start=math.radians(20.0), lo=-0.425, hi=1.097, rate=0.15 / 0.438, sign=1,
                 flow=101.8, pressure=(95.0, 12.0)),
    "tilt": dict(start=math.radians(-70.0), lo=-2.75, hi=-0.25, rate=0.15 / 0.308, sign=-1,
                 flow=93.5, pressure=(60.0, 15.0)),
    "extension": dict(start=1.0, lo=0.0, hi=3.7, rate=0.40 / 0.5, sign=1, flow=54.2,
                      pressure=(35.0, 10.0)),
}
# The K70M's proportional sections (hydraulics.valves.dead_zone): no flow below 53 % of the spool
# range, then linear to full flow. craneassist adds this dead zone to its commands.
DEAD_ZONE = 0.53
# The load-sensing pump: standby pressure with every section closed, else the highest load plus
# the margin (hydraulics.pump: standby 2 MPa, ls_margin 3 MPa).
PUMP_STANDBY_BAR = 20.0
PUMP_MARGIN_BAR = 30.0

# Units a DBC may state, to SI.
UNIT_SCALE = {
    "rad": 1.0, "deg": math.pi / 180.0, "m": 1.0, "mm": 1e-3, "cm": 1e-2,
    "Pa": 1e-5, "kPa": 1e-2, "MPa": 10.0, "bar": 1.0,  # pressures to bar
    "L/min": 1.0, "m^3/s": 60000.0,  # flows to L/min
    "%": 1.0, "": 1.0, "1": 1.0,  # valve replies, DM1, NAME fields: as the DBC states them
}
# The peer's own J1939 NAME for the valve group's address claim (any value; it only has to be a
# NAME): identity number 0x2A, function 129, industry group 2.
PEER_NAME = dict(IdentityNumber=0x2A, ManufacturerCode=0, EcuInstance=0, FunctionInstance=0,
                 Function=129, Reserved=0, VehicleSystem=0, VehicleSystemInstance=0, IndustryGroup=2,
                 ArbitraryAddressCapable=0)
ISO_STATES = {0: "block", 1: "extend", 2: "retract", 3: "float", 15: "dont_care"}
FAIL_SAFE_CODES = {"block": 0, "float": 1}
HEARTBEAT_ENABLED = 1
HEARTBEAT_FAULT = 2


def say(text):
    print(f"valve_peer: {text}", flush=True)


def hex_id(ident, extended):
    return f"{ident:08X}" if extended else f"{ident:03X}"


class Stats:
    """Intervals between the kernel receive timestamps of one message, counted while craneassist's
    loop runs (heartbeat enabled): the block commands at the start and at the end go out off the
    cycle, at once."""

    def __init__(self):
        self.last = None
        self.intervals = []

    def add(self, stamp, running=True):
        if self.last is not None and running:
            self.intervals.append(stamp - self.last)
        self.last = stamp

    def text(self, nominal_s):
        if not self.intervals:
            return "no intervals"
        v = self.intervals
        mean = statistics.fmean(v)
        std = statistics.pstdev(v) if len(v) > 1 else 0.0
        return (f"period mean {mean * 1e3:.2f} ms, std dev {std * 1e3:.2f} ms, max gap "
                f"{max(v) * 1e3:.1f} ms, min {min(v) * 1e3:.1f} ms over {len(v)} intervals"
                + (f" (DBC GenMsgCycleTime {nominal_s * 1e3:g} ms)" if nominal_s else ""))

    def mean(self):
        return statistics.fmean(self.intervals) if self.intervals else None


class Section:
    """One valve section: an ISO 11783-7 AVC message or a signal output."""

    def __init__(self, frame, joint, kind):
        self.frame = frame
        self.joint = joint
        self.kind = kind  # "avc" or "signal"
        self.name = frame.name
        self.cycle_s = (frame.cycle_time or 0) / 1000.0
        self.stats = Stats()
        self.count = 0
        self.spool = 0.0  # as commanded
        self.last_rx = None  # monotonic time of the last command
        self.last_stamp = None  # its kernel receive timestamp (wall clock)
        self.last_data = None
        self.last_text = "none"
        self.last_blocked = None
        self.fail_safe = None  # why the section is in fail-safe, or None
        self.events = []
        self.max_flow = 0.0
        self.max_ext_diff = 0.0
        self.fail_safe_modes = set()
        self.resolution_modes = set()
        if kind == "signal":
            sig = frame.signals[0]
            self.signal = sig
            self.full_scale = max(abs(float(sig.min)), abs(float(sig.max)))
        # Reserved bits: those no DBC signal covers, found by encoding every signal all ones.
        ones = {s.name: (-1 if s.is_signed else (1 << s.size) - 1) for s in frame.signals}
        covered = int.from_bytes(bytes(frame.encode(ones)), "little")
        self.reserved_mask = ~covered & ((1 << (8 * frame.size)) - 1)


class Peer:
    def __init__(self, args):
        self.args = args
        self.db = canmatrix.formats.loadp_flat(args.dbc)
        self.frames = {(f.arbitration_id.id, f.arbitration_id.extended): f for f in self.db.frames}
        self.failures = []
        self.sections = {}  # (id, extended) -> Section
        self.heartbeat = None
        self.claim_frame = None
        self.claims = []  # (monotonic time, NAME) of craneassist's address claims
        self.first_section_command = None
        self.feedback = []  # (frame, [(signal, getter)], period in s: 0 every tick, None once)
        self.next_send = {}
        self.reserved = {}
        self.joint_state = {}
        self.unknown = {}
        self.foreign = {}
        self.violations = {}
        self.hb = dict(count=0, stats=Stats(), last=None, last_state=None, last_adv=None,
                       last_adv_stamp=None, skips=0, repeats=0, faults=0, alive=False,
                       states=set(), fault_reasons=set())
        self.flow_while_not_enabled = 0
        self.sent = 0
        self.send_times = []
        self.overruns = 0
        self.encode_cache = {}
        self.decode_cache = {}
        self.encodings = 0
        self.busy = []  # seconds of work per tick
        self.first_command = None
        self.last_command = None
        self.motion_seen = False
        self.stop = False
        self._build()

    # --- the DBC ----------------------------------------------------------------------------
    def _build(self):
        machine_signals = {}
        for f in self.db.frames:
            key = (f.arbitration_id.id, f.arbitration_id.extended)
            names = {s.name for s in f.signals}
            if "craneassist" in f.transmitters:
                if {"PortFlowCommand", "ValveState"} <= names:
                    m = re.search(r"joint (\w+)", f.comment or "")
                    if not m:
                        sys.exit(f"valve_peer: {f.name}: no 'joint NAME' in its DBC comment")
                    self.sections[key] = Section(f, m.group(1), "avc")
                elif "AliveCounter" in names:
                    self.heartbeat = f
                elif "IdentityNumber" in names:
                    self.claim_frame = f  # craneassist's J1939 address claim
                elif f.name.endswith("_valve_command") and len(f.signals) == 1:
                    self.sections[key] = Section(f, f.name[: -len("_valve_command")], "signal")
                else:
                    sys.exit(f"valve_peer: {f.name}: a craneassist message this peer does not know")
            else:
                for s in f.signals:
                    machine_signals[(f.name, s.name)] = (f, s)
        for sec in self.sections.values():
            if sec.joint not in JOINTS:
                sys.exit(f"valve_peer: {sec.name}: joint '{sec.joint}' not in the joint table")
        for joint, j in JOINTS.items():
            if (f"{joint}_position", f"{joint}_position") not in machine_signals:
                sys.exit(f"valve_peer: the DBC has no {joint}_position signal")
            self.joint_state[joint] = dict(q=j["start"], open=0.0)
        # Every machine message with the value each of its signals reports.
        by_frame = {}
        for name, (f, s) in machine_signals.items():
            by_frame.setdefault(f.name, (f, []))[1].append(s)
        for f, sigs in by_frame.values():
            getters = []
            for s in sigs:
                if s.unit not in UNIT_SCALE:
                    sys.exit(f"valve_peer: {f.name}.{s.name}: unit '{s.unit}' not known")
                getters.append((s, self._getter(f, s)))
            # Positions, pressures, the pump and the valves' replies every tick; DM1 at its
            # cycle (1 s); the valve group's address claim once, at the start.
            period = 0.0
            if f.name.startswith("AddressClaimed"):
                period = None
            elif f.name.startswith("DM1_"):
                period = (f.cycle_time or 1000) / 1000.0
            self.feedback.append((f, getters, period))
        self.feedback.sort(key=lambda item: item[0].name)
        # The heartbeat's timeout: the DBC comment states it ("... not advanced for 100 ms").
        self.hb_timeout = self.args.heartbeat_timeout
        if self.heartbeat is not None and self.hb_timeout is None:
            m = re.search(r"(\d+(?:\.\d+)?)\s*ms", self.heartbeat.comment or "")
            self.hb_timeout = float(m.group(1)) / 1000.0 if m else 0.1
        self.hb_cycle_s = (self.heartbeat.cycle_time or 0) / 1000.0 if self.heartbeat else 0.0

    def _section_of(self, frame):
        m = re.search(r"joint (\w+)", frame.comment or "")
        for sec in self.sections.values():
            if m and sec.joint == m.group(1):
                return sec
        sys.exit(f"valve_peer: {frame.name}: no valve section named in its DBC comment")

    def _getter(self, frame, signal):
        name = signal.name
        if frame.name.startswith("AuxValveEstimatedFlow"):
            # The valve's own report of what it does: its effective spool (0 in fail-safe).
            sec = self._section_of(frame)
            spool = lambda: self.effective_spool(sec)  # noqa: E731
            return {
                "ExtendPortEstimatedFlow": lambda: max(spool(), 0.0) * 100.0,
                "RetractPortEstimatedFlow": lambda: max(-spool(), 0.0) * 100.0,
                "ValveState": lambda: 1 if spool() > 0 else (2 if spool() < 0 else 0),
                "FailSafeMode": lambda: FAIL_SAFE_CODES[self.args.fail_safe],
                "LimitStatus": lambda: 0,
            }.get(name) or sys.exit(f"valve_peer: {frame.name}.{name}: not known")
        if frame.name.startswith("DM1_"):  # no active fault: lamps off, no DTC, no flash
            return lambda: 255 if name == "LampFlash" else 0
        if frame.name.startswith("AddressClaimed"):
            if name not in PEER_NAME:
                sys.exit(f"valve_peer: {frame.name}.{name}: not a NAME field")
            return lambda: PEER_NAME[name]
        if name.endswith("_valve_status"):  # the driver's status: its value named "ok"
            ok = [v for v, text in (signal.values or {}).items() if text == "ok"]
            if not ok:
                sys.exit(f"valve_peer: {frame.name}.{name}: no value named ok")
            return lambda: int(ok[0])
        m = re.fullmatch(r"(\w+)_(position|pressure_a|pressure_b)", name)
        if m and m.group(1) in JOINTS:
            joint, what = m.group(1), m.group(2)
            if what == "position":
                return lambda: self.joint_state[joint]["q"]
            side = 0 if what == "pressure_a" else 1
            return lambda: JOINTS[joint]["pressure"][side]
        if name == "pump_pressure":
            return self._pump_pressure
        if name == "pump_flow":
            return self._pump_flow
        if name in ("grapple_swing_radial", "grapple_swing_tangential"):
            return lambda: 0.0  # the peer's grapple hangs still (a swing sensor reading 0 deg)
        sys.exit(f"valve_peer: machine signal '{name}': the peer does not know what to send")

    def _pump_pressure(self):
        loads = [JOINTS[j]["pressure"][0] for j, s in self.joint_state.items() if s["open"] > 0]
        return max(loads) + PUMP_MARGIN_BAR if loads else PUMP_STANDBY_BAR

    def _pump_flow(self):
        return sum(JOINTS[j]["flow"] * s["open"] for j, s in self.joint_state.items())

    # --- checks -----------------------------------------------------------------------------
    def violation(self, what):
        n = self.violations.get(what, 0)
        self.violations[what] = n + 1
        if n == 0:
            say(f"VIOLATION: {what}")

    def on_frame(self, msg, now):
        key = (msg.arbitration_id, msg.is_extended_id)
        frame = self.frames.get(key)
        if frame is None:
            self.unknown[key] = self.unknown.get(key, 0) + 1
            return
        if "craneassist" not in frame.transmitters:
            self.foreign[frame.name] = self.foreign.get(frame.name, 0) + 1  # someone else's
            return
        data = bytes(msg.data)
        if len(data) != frame.size:
            self.violation(f"{frame.name}: dlc {len(data)}, the DBC says {frame.size}")
            return
        if self.first_command is None:
            self.first_command = now
        self.last_command = now
        values = self.decode_cache.get((key, data))
        if values is None:  # canmatrix decodes each distinct payload once
            values = frame.decode(data)
            if len(self.decode_cache) > 4096:
                self.decode_cache.clear()
            self.decode_cache[(key, data)] = values
        if frame is self.heartbeat:
            self.on_heartbeat(values, msg.timestamp, now)
            return
        if frame is self.claim_frame:
            word = int.from_bytes(data, "little")
            if self.claims and self.claims[-1][1] != word:
                self.violation(f"{frame.name}: the NAME changed ({word:#018x})")
            if any(sec.count for sec in self.sections.values()):
                self.violation(f"{frame.name}: a claim after valve commands")
            self.claims.append((now, word))
            return
        sec = self.sections[key]
        if self.first_section_command is None:
            self.first_section_command = now
        sec.count += 1
        sec.stats.add(msg.timestamp, self.loop_running())
        sec.last_rx = now
        sec.last_stamp = msg.timestamp
        if data == sec.last_data:  # the same command again: decoded and checked already
            spool = sec.spool
        elif sec.kind == "avc":
            spool = self.check_avc(sec, values, data)
        else:
            spool = self.check_signal(sec, values)
        sec.last_data = data
        if spool != 0.0 and not self.loop_running():
            self.flow_while_not_enabled += 1
        sec.spool = spool
        if sec.fail_safe is not None:
            say(f"{sec.joint} ({sec.name}): commands again after fail-safe ({sec.fail_safe})")
            sec.fail_safe = None

    def check_avc(self, sec, values, data):
        raw = {k: int(v.raw_value) for k, v in values.items()}
        flow = float(values["PortFlowCommand"].phys_value)
        state = raw["ValveState"]
        mode = raw["ResolutionMode"]
        name = sec.name
        if raw["PortFlowCommand"] > 250:
            self.violation(f"{name}: PortFlowCommand raw {raw['PortFlowCommand']} above 250 "
                           "(100 %)")
        if state not in (0, 1, 2):
            self.violation(f"{name}: ValveState {state} ({ISO_STATES.get(state, '?')}), "
                           "not block/extend/retract")
        if (state == 0) != (raw["PortFlowCommand"] == 0):
            self.violation(f"{name}: ValveState {ISO_STATES.get(state, state)} "
                           f"with flow {flow:g} %")
        sec.fail_safe_modes.add(raw["FailSafeMode"])
        if raw["FailSafeMode"] != FAIL_SAFE_CODES[self.args.fail_safe]:
            self.violation(f"{name}: FailSafeMode {raw['FailSafeMode']}, expected "
                           f"{FAIL_SAFE_CODES[self.args.fail_safe]} ({self.args.fail_safe})")
        sec.resolution_modes.add(mode)
        ext_raw = raw["PortFlowCommandExtended"]
        if mode == 1:
            if ext_raw > 64000:
                self.violation(f"{name}: PortFlowCommandExtended raw {ext_raw} above 64000 "
                               "(100 %)")
            else:
                ext = float(values["PortFlowCommandExtended"].phys_value)
                diff = abs(ext - flow)
                sec.max_ext_diff = max(sec.max_ext_diff, diff)
                if diff > 0.4 + 1e-9:
                    self.violation(f"{name}: extended flow {ext:g} % vs 8-bit {flow:g} %: more "
                                   "than one 8-bit step apart")
                if state == 0 and ext_raw != 0:
                    self.violation(f"{name}: block with extended flow raw {ext_raw}")
        elif mode == 0:
            if ext_raw != 0xFFFF:
                self.violation(f"{name}: resolution mode 0 but PortFlowCommandExtended raw "
                               f"{ext_raw:#x}, not 0xFFFF")
        else:
            self.violation(f"{name}: ResolutionMode {mode}, expected 0 or 1")
        word = int.from_bytes(data, "little")
        if word & sec.reserved_mask != sec.reserved_mask:
            self.violation(f"{name}: reserved bits not all 1 ({data.hex().upper()})")
        sec.max_flow = max(sec.max_flow, flow)
        spool = 0.0
        if state == 1:
            spool = flow / 100.0
        elif state == 2:
            spool = -flow / 100.0
        sec.last_blocked = state == 0 and raw["PortFlowCommand"] == 0
        sec.last_text = f"{ISO_STATES.get(state, state)} {flow:g} %"
        return spool

    def check_signal(self, sec, values):
        value = float(values[sec.signal.name].phys_value)
        lo, hi = float(sec.signal.min), float(sec.signal.max)
        if not lo <= value <= hi:
            self.violation(f"{sec.name}: {value:g} {sec.signal.unit} outside [{lo:g}, {hi:g}]")
        sec.max_flow = max(sec.max_flow, abs(value) / sec.full_scale * 100.0)
        sec.last_blocked = value == 0
        sec.last_text = f"{value:g} {sec.signal.unit}"
        return max(-1.0, min(1.0, value / sec.full_scale))

    def loop_running(self):
        return self.heartbeat is None or self.hb["last_state"] == HEARTBEAT_ENABLED

    def on_heartbeat(self, values, stamp, now):
        hb = self.hb
        counter = int(values["AliveCounter"].raw_value)
        state = int(values["State"].raw_value)
        reason = int(values["FaultReason"].raw_value)
        hb["count"] += 1
        hb["stats"].add(stamp, state == HEARTBEAT_ENABLED and hb["last_state"] == HEARTBEAT_ENABLED)
        hb["states"].add(state)
        if state == HEARTBEAT_FAULT:
            hb["faults"] += 1
            hb["fault_reasons"].add(reason)
        elif reason != 0:
            self.violation(f"heartbeat: FaultReason {reason} in state {state}")
        advanced = hb["last"] is None or counter == (hb["last"] + 1) % 256
        if hb["last"] is not None and counter == hb["last"]:
            hb["repeats"] += 1
            self.violation(f"heartbeat: AliveCounter repeated ({counter})")
        elif not advanced:
            hb["skips"] += 1
            self.violation(f"heartbeat: AliveCounter {hb['last']} -> {counter}")
        hb["last"] = counter
        hb["last_state"] = state
        if advanced:
            hb["last_adv"] = now
            hb["last_adv_stamp"] = stamp
        hb["alive"] = advanced and state == HEARTBEAT_ENABLED

    # --- the machine ------------------------------------------------------------------------
    def supervise(self, now, wall):
        """Fail-safe on silence: per section, and for every section on the heartbeat."""
        if self.heartbeat is not None and self.hb["last_adv"] is not None:
            silent = now - self.hb["last_adv"]
            if silent > self.hb_timeout and not self.hb.get("lost_reported"):
                self.hb["lost_reported"] = True
                was_enabled = self.hb["last_state"] == HEARTBEAT_ENABLED
                after = wall - self.hb["last_adv_stamp"]
                say(f"heartbeat lost: AliveCounter not advanced for {after * 1e3:.1f} ms "
                    f"(timeout {self.hb_timeout * 1e3:g} ms; last state "
                    f"{'enabled' if was_enabled else self.hb['last_state']}): every section to "
                    "fail-safe")
                for sec in self.sections.values():
                    self.enter_fail_safe(sec, wall, "heartbeat lost")
            elif silent <= self.hb_timeout:
                self.hb["lost_reported"] = False
            if silent > self.hb_timeout:
                self.hb["alive"] = False
        timeout = self.args.command_timeout
        for sec in self.sections.values():
            if sec.last_rx is not None and now - sec.last_rx > timeout:
                self.enter_fail_safe(sec, wall, f"no command for {timeout * 1e3:g} ms")

    def enter_fail_safe(self, sec, wall, why):
        if sec.fail_safe is not None or sec.last_stamp is None:
            return
        moving = sec.spool != 0.0  # commanded open when its commands stopped
        sec.fail_safe = why
        after = wall - sec.last_stamp
        sec.events.append(dict(wall=wall, after=after, why=why, moving=moving, spool=sec.spool))
        was = f"MOVING at spool {sec.spool:.3f}" if moving else "blocked"
        say(f"{sec.joint} ({sec.name}): fail-safe {self.args.fail_safe} (spool 0) "
            f"{after * 1e3:.1f} ms after its last command: {why}; it was {was}")

    def effective_spool(self, sec):
        """The spool the section moves with: 0 in fail-safe or while the heartbeat is not alive."""
        if sec.fail_safe is not None:
            return 0.0
        if self.heartbeat is not None and not self.hb["alive"]:
            return 0.0
        return sec.spool

    def integrate(self, dt):
        for sec in self.sections.values():
            u = self.effective_spool(sec)
            j = JOINTS[sec.joint]
            opening = max(0.0, min(1.0, (abs(u) - DEAD_ZONE) / (1.0 - DEAD_ZONE)))
            st = self.joint_state[sec.joint]
            st["open"] = opening
            if opening > 0.0 and not self.motion_seen:
                self.motion_seen = True
                if self.args.motion_file:
                    with open(self.args.motion_file, "w") as f:
                        f.write(f"{sec.joint}\n")
            rate = math.copysign(opening * j["rate"], u) * j["sign"]
            st["q"] = max(j["lo"], min(j["hi"], st["q"] + rate * dt))

    def message(self, frame, getters):
        """The frame with the values the getters give now, encoded by canmatrix; the same values
        give the same (cached) python-can message, which saves the emulated CPU most of the work
        while the crane stands still."""
        raws = []
        for s, get in getters:
            value = get() / UNIT_SCALE[s.unit]
            value = max(float(s.min), min(float(s.max), value))
            raws.append(int(round((value - float(s.offset)) / float(s.factor))))
        key = (frame.name, tuple(raws))
        msg = self.encode_cache.get(key)
        if msg is None:
            # canmatrix 0.9.5's Frame.encode takes raw values.
            data = bytes(frame.encode({s.name: r for (s, _), r in zip(getters, raws)}))
            if frame.is_j1939:  # J1939: bits no signal covers are reserved, sent as 1
                data = (int.from_bytes(data, "little") | self.reserved_bits(frame)).to_bytes(
                    len(data), "little")
            msg = can.Message(arbitration_id=frame.arbitration_id.id,
                              is_extended_id=frame.arbitration_id.extended, data=data)
            if len(self.encode_cache) > 4096:
                self.encode_cache.clear()
            self.encode_cache[key] = msg
            self.encodings += 1
        return msg

    def reserved_bits(self, frame):
        mask = self.reserved.get(frame.name)
        if mask is None:
            ones = {s.name: (-1 if s.is_signed else (1 << s.size) - 1) for s in frame.signals}
            covered = int.from_bytes(bytes(frame.encode(ones)), "little")
            mask = ~covered & ((1 << (8 * frame.size)) - 1)
            self.reserved[frame.name] = mask
        return mask

    def send_feedback(self, bus, now):
        for frame, getters, period in self.feedback:
            due = self.next_send.get(frame.name, now)
            if due is None or now < due:
                continue
            self.next_send[frame.name] = None if period is None else now + period
            try:
                bus.send(self.message(frame, getters))
                self.sent += 1
            except can.CanError as e:
                self.violation(f"send {frame.name}: {e}")
        self.send_times.append(now)

    # --- the loop ---------------------------------------------------------------------------
    def run(self):
        args = self.args
        bus = can.interface.Bus(channel=args.channel, interface=args.interface)
        say(f"{args.dbc}: {len(self.sections)} valve sections "
            f"({', '.join(f'{s.joint}={s.name}' for s in self.sections.values())}), "
            f"heartbeat {self.heartbeat.name if self.heartbeat else 'none'}"
            f"{f' (timeout {self.hb_timeout * 1e3:g} ms)' if self.heartbeat else ''}, "
            f"{len(self.feedback)} feedback messages every {args.period * 1e3:g} ms on "
            f"{args.channel}")
        start = time.monotonic()
        next_tick = start
        last_tick = start
        ready = False
        try:
            while not self.stop:
                now = time.monotonic()
                if now < next_tick:
                    # Sleep to the tick and take the waiting frames then: one wake-up per tick
                    # instead of one per frame. Their kernel timestamps keep the timing exact.
                    time.sleep(next_tick - now)
                    continue
                wall = time.time()
                while True:
                    msg = bus.recv(timeout=0)
                    if msg is None:
                        break
                    # The monotonic time of its arrival, from its kernel (wall clock) timestamp.
                    self.on_frame(msg, now - max(0.0, wall - msg.timestamp))
                self.supervise(now, wall)
                self.integrate(now - last_tick)
                last_tick = now
                self.send_feedback(bus, now)
                self.busy.append(time.monotonic() - now)
                if not ready:
                    ready = True
                    if args.ready_file:
                        with open(args.ready_file, "w") as f:
                            f.write(f"{os.getpid()}\n")
                    say(f"sending feedback ({time.monotonic() - start:.2f} s after opening "
                        "the bus)")
                next_tick += args.period
                if next_tick < now:  # overrun: count it, do not burst to catch up
                    self.overruns += 1
                    next_tick = now + args.period
                silent = now - self.last_command if self.last_command is not None else 0.0
                if silent > args.exit_after_silence:
                    say(f"craneassist silent for {args.exit_after_silence:g} s: done")
                    break
                if self.first_command is None and now - start > args.start_timeout:
                    self.failures.append(f"no frame from craneassist within "
                                         f"{args.start_timeout:g} s")
                    break
                if now - start > args.max_time:
                    say(f"--max-time {args.max_time:g} s reached")
                    break
        finally:
            bus.shutdown()
        return self.report()

    # --- the summary ------------------------------------------------------------------------
    def report(self):
        fail = self.failures
        say("--- summary")
        self.report_sections(fail)
        if self.heartbeat is not None:
            self.report_heartbeat(fail)
        self.report_feedback(fail)
        if self.claim_frame is not None:
            self.report_claim(fail)
        if self.unknown:
            fail.append("frames foreign to the DBC: " + ", ".join(
                f"{hex_id(i, e)} x{n}" for (i, e), n in sorted(self.unknown.items())))
        if self.foreign:
            fail.append("another node sent the machine's messages: " + ", ".join(
                f"{k} x{n}" for k, n in sorted(self.foreign.items())))
        for what, n in sorted(self.violations.items()):
            fail.append(f"{what} (x{n})")
        self.report_silence(fail)
        if not self.motion_seen:
            fail.append("no section ever moved")
        for f in fail:
            say(f"FAIL: {f}")
        say("PASS: every check" if not fail else f"FAIL: {len(fail)} checks failed")
        return 1 if fail else 0

    def report_claim(self, fail):
        """J1939-81: craneassist claims its address, then waits 250 ms before it sends from it."""
        if not self.claims:
            fail.append(f"{self.claim_frame.name}: craneassist never claimed its address")
            return
        last = self.claims[-1][0]
        gap = (self.first_section_command - last) * 1e3 if self.first_section_command else None
        say(f"address claim: {len(self.claims)} claims, NAME {self.claims[-1][1]:#018x}; the first "
            f"valve command {gap:.0f} ms after the last claim" if gap is not None else
            f"address claim: {len(self.claims)} claims, no valve command")
        if gap is not None and gap < 250.0 - 5.0:  # 5 ms: the peer's own tick
            fail.append(f"a valve command {gap:.0f} ms after the address claim (J1939-81: 250 ms)")

    def period_ok(self, what, stats, nominal_s, fail):
        mean = stats.mean()
        tol = self.args.cycle_tolerance
        if nominal_s and mean is not None and abs(mean - nominal_s) > tol * nominal_s:
            fail.append(f"{what}: mean period {mean * 1e3:.2f} ms, DBC {nominal_s * 1e3:g} ms "
                        f"(tolerance {tol * 100:g} %)")

    def report_sections(self, fail):
        for sec in self.sections.values():
            ident = hex_id(sec.frame.arbitration_id.id, sec.frame.arbitration_id.extended)
            say(f"{sec.joint} ({sec.name} {ident}): {sec.count} commands, "
                f"{sec.stats.text(sec.cycle_s)}")
            extra = ""
            if sec.kind == "avc":
                extra = (f", fail-safe modes {sorted(sec.fail_safe_modes)}, resolution modes "
                         f"{sorted(sec.resolution_modes)}, extended vs 8-bit flow max diff "
                         f"{sec.max_ext_diff:.3f} %")
            say(f"  largest flow {sec.max_flow:.1f} %{extra}; last command {sec.last_text}; "
                f"position {self.joint_state[sec.joint]['q']:.4f}")
            if sec.count == 0:
                fail.append(f"{sec.name}: no command")
            self.period_ok(sec.name, sec.stats, sec.cycle_s, fail)

    def report_heartbeat(self, fail):
        hb = self.hb
        reasons = sorted(hb["fault_reasons"])
        say(f"heartbeat ({self.heartbeat.name}): {hb['count']} messages, "
            f"{hb['stats'].text(self.hb_cycle_s)}; counter skips {hb['skips']}, repeats "
            f"{hb['repeats']}; states seen {sorted(hb['states'])}"
            f"{f'; fault reasons {reasons}' if hb['faults'] else ''}; commands asking for flow "
            f"while not enabled: {self.flow_while_not_enabled}")
        if hb["count"] == 0:
            fail.append("no heartbeat")
        self.period_ok("heartbeat", hb["stats"], self.hb_cycle_s, fail)
        if hb["skips"] or hb["repeats"]:
            fail.append("heartbeat counter skipped or repeated")
        if hb["faults"]:
            fail.append(f"craneassist reported a fault in its heartbeat (reasons {reasons})")
        if self.flow_while_not_enabled:
            fail.append(f"{self.flow_while_not_enabled} commands asked for flow while the "
                        "heartbeat was not enabled")

    def report_feedback(self, fail):
        gaps = [b - a for a, b in zip(self.send_times, self.send_times[1:])]
        if not gaps:
            return
        period = self.args.period
        mean = statistics.fmean(gaps)
        say(f"feedback sent: {self.sent} frames, {len(self.send_times)} rounds, period mean "
            f"{mean * 1e3:.2f} ms, std dev {statistics.pstdev(gaps) * 1e3:.2f} ms, max "
            f"{max(gaps) * 1e3:.1f} ms (nominal {period * 1e3:g} ms), overruns {self.overruns}; "
            f"{self.encodings} encodings; work per tick mean "
            f"{statistics.fmean(self.busy) * 1e3:.2f} ms, max {max(self.busy) * 1e3:.1f} ms")
        if mean > 2 * period:
            fail.append(f"feedback period mean {mean * 1e3:.2f} ms: the peer did not keep up")

    def report_silence(self, fail):
        args = self.args
        moving = []
        for sec in self.sections.values():
            for e in sec.events:
                say(f"fail-safe: {sec.joint} {e['after'] * 1e3:.1f} ms after its last command "
                    f"({e['why']}), {'moving' if e['moving'] else 'already blocked'}")
                if e["moving"]:
                    moving.append((sec, e))
        if not args.expect_silence:
            for sec, e in moving:
                fail.append(f"{sec.joint}: commands stopped while it moved ({e['why']})")
            for sec in self.sections.values():
                if sec.count and not sec.last_blocked:
                    fail.append(f"{sec.joint}: last command {sec.last_text}, not block")
            commanded = [sec for sec in self.sections.values() if sec.count]
            if commanded and all(sec.last_blocked for sec in commanded):
                say("every section's last command: block")
            return
        timeout = min(args.command_timeout, self.hb_timeout or args.command_timeout)
        limit = timeout + args.tolerance
        if not moving:
            fail.append("--expect-silence: no section was moving when the commands stopped")
        for sec, e in moving:
            if e["after"] > limit:
                fail.append(f"{sec.joint}: fail-safe {e['after'] * 1e3:.1f} ms after its last "
                            f"command (allowed {limit * 1e3:.0f} ms)")
        if moving:
            worst = max(e["after"] for _, e in moving)
            say(f"fail-safe on silence: {len(moving)} moving sections to spool 0, the last "
                f"{worst * 1e3:.1f} ms after its last command (timeouts: commands "
                f"{args.command_timeout * 1e3:g} ms, heartbeat "
                f"{(self.hb_timeout or 0) * 1e3:g} ms)")
        for sec in self.sections.values():
            if self.effective_spool(sec) != 0.0:
                fail.append(f"{sec.joint}: not in fail-safe at the end")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("dbc", help="the DBC craneassist can dbc writes")
    ap.add_argument("--channel", default="vcan0")
    ap.add_argument("--interface", default="socketcan", help="python-can interface")
    ap.add_argument("--period", type=float, default=0.01, help="feedback period, s")
    ap.add_argument("--command-timeout", type=float, default=0.1,
                    help="a section without a command for this long goes to fail-safe, s")
    ap.add_argument("--heartbeat-timeout", type=float, default=None,
                    help="s; default: the DBC's heartbeat comment, else 0.1")
    ap.add_argument("--fail-safe", choices=sorted(FAIL_SAFE_CODES), default="block",
                    help="the fail-safe mode the commands must carry (the mapping's)")
    ap.add_argument("--expect-silence", action="store_true",
                    help="craneassist will be killed while moving: expect fail-safe on silence")
    ap.add_argument("--tolerance", type=float, default=0.05,
                    help="allowed lateness of the fail-safe beyond its timeout, s")
    ap.add_argument("--cycle-tolerance", type=float, default=0.1,
                    help="allowed deviation of a mean command period from the DBC's, fraction")
    ap.add_argument("--exit-after-silence", type=float, default=1.0,
                    help="end this long after craneassist's last frame, s")
    ap.add_argument("--start-timeout", type=float, default=60.0,
                    help="fail when craneassist sends nothing for this long from the start, s")
    ap.add_argument("--max-time", type=float, default=300.0)
    ap.add_argument("--ready-file", help="written once the first feedback is sent")
    ap.add_argument("--motion-file", help="written once a section first moves")
    args = ap.parse_args()
    peer = Peer(args)

    def on_signal(signum, _frame):
        peer.stop = True

    signal.signal(signal.SIGTERM, on_signal)
    signal.signal(signal.SIGINT, on_signal)
    return peer.run()


if __name__ == "__main__":
    sys.exit(main())
