#!/usr/bin/python3
"""Decodes a craneassist --can-log (candump -L lines with candump -x's T/R marks) with
independent tools: python-can reads the log, canmatrix decodes every frame through a DBC
(the one `craneassist can dbc` writes). Neither shares code with craneassist's codecs.

Checks, each counted and printed; the exit status is 1 when any fails:
  - every frame is a message of the DBC (no unknown identifiers);
  - every frame was sent by the node the DBC names as its sender: craneassist's messages are
    marked T (sent), the machine's R (received);
  - every decoded value lies within its signal's [min, max];
  - with --moving: some valve command asks for flow (the run moved the crane);
  - with --ends-blocked: the last command of every ISO 11783 valve is block with flow 0 and the
    last current command is 0.

Usage: decode_can_log.py DBC LOG [--moving] [--ends-blocked]
Debian 12: apt install python3-can python3-canmatrix
"""
import argparse
import collections
import logging
import sys
import warnings

warnings.filterwarnings("ignore", category=SyntaxWarning)  # canmatrix 0.9.5's own code
logging.getLogger("canmatrix").setLevel(logging.ERROR)
import can  # noqa: E402
import canmatrix  # noqa: E402
import canmatrix.formats  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("dbc")
    ap.add_argument("log")
    ap.add_argument("--moving", action="store_true")
    ap.add_argument("--ends-blocked", action="store_true")
    args = ap.parse_args()

    db = canmatrix.formats.loadp_flat(args.dbc)
    frames = {(f.arbitration_id.id, f.arbitration_id.extended): f for f in db.frames}

    counts = collections.Counter()
    unknown = collections.Counter()
    wrong_direction = collections.Counter()
    out_of_range = collections.Counter()
    marked = 0
    last = {}
    moving = 0
    for msg in can.LogReader(args.log):
        frame = frames.get((msg.arbitration_id, msg.is_extended_id))
        if frame is None:
            unknown[(msg.arbitration_id, msg.is_extended_id)] += 1
            continue
        counts[frame.name] += 1
        # python-can reads candump -x's mark into is_rx (True without a mark).
        sent_by_craneassist = "craneassist" in frame.transmitters
        if sent_by_craneassist == msg.is_rx:
            wrong_direction[frame.name] += 1
        marked += 1
        values = frame.decode(bytes(msg.data))
        for name, value in values.items():
            sig = value.signal
            lo, hi = float(sig.min), float(sig.max)
            phys = float(value.phys_value)
            if lo != hi and not (lo - 1e-9 <= phys <= hi + 1e-9):
                out_of_range[f"{frame.name}.{name}={phys:g} not in [{lo:g}, {hi:g}]"] += 1
        last[frame.name] = {k: float(v.phys_value) for k, v in values.items()}
        if frame.name.startswith("AuxValveCommand") and last[frame.name]["PortFlowCommand"] > 0:
            moving += 1
        elif frame.name.endswith("_valve_command") and last[frame.name][frame.signals[0].name] != 0:
            moving += 1

    failures = 0
    print(f"{args.log}: {sum(counts.values())} frames decoded with {args.dbc}, "
          f"{sum(unknown.values())} unknown")
    for name in sorted(counts):
        print(f"  {name}: {counts[name]}")
    if unknown:
        failures += 1
        for (ident, ext), n in unknown.most_common(10):
            print(f"FAIL: unknown identifier {ident:0{8 if ext else 3}X}: {n} frames")
    if wrong_direction:
        failures += 1
        for name, n in wrong_direction.items():
            print(f"FAIL: {name}: {n} frames marked in the wrong direction")
    if out_of_range:
        failures += 1
        for what, n in out_of_range.most_common(10):
            print(f"FAIL: {what} ({n} frames)")
    if args.moving:
        print(f"valve commands asking for flow: {moving}")
        if moving == 0:
            failures += 1
            print("FAIL: no valve command asked for flow")
    if args.ends_blocked:
        for name, values in sorted(last.items()):
            if name.startswith("AuxValveCommand"):
                ok = values["ValveState"] == 0 and values["PortFlowCommand"] == 0
            elif name.endswith("_valve_command"):
                ok = all(v == 0 for v in values.values())
            else:
                continue
            print(f"last {name}: {values} {'block' if ok else 'NOT BLOCKED'}")
            if not ok:
                failures += 1
    print("decode:", "FAIL" if failures else "PASS")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
