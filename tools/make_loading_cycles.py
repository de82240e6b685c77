#!/usr/bin/env python3
"""Writes the forestry loading-cycle replays of the loading benchmark (docs/sway.md, "The loading
cycle as a benchmark"; examples/replays/loading.yaml): reach out to the log, lower onto it, wait
for the grapple to settle, grab it, lift and pull in, slew 90 degrees to the bunk, wait for the
grapple to settle, lower, release, rise and slew back. Standard library only.

  tools/make_loading_cycles.py [OUTDIR]   (default examples/replays/loading)

The tip velocity is in the crane frame (x out, y up, z across); a slew is an arc about the slew
axis, written as a row every 0.1 s. Each cycle starts from the K70M's default pose (the tip 5.4 m
out, 0.65 m up) and ends back above it. The loads are logs of a forestry loader: 350 kg near the
machine, 400 kg at 7 m (84 % of the K70M's chart there), and 700 kg at 6 m, 107 % of the chart:
more than the crane may lift there, so the rated capacity limiter trips and pulling in frees it.
"""
import math
import os
import sys

START_REACH_M = 5.4
ROW_S = 0.1  # rows of an arc


class Cycle:
    def __init__(self):
        self.t = 0.0
        self.reach = START_REACH_M
        self.angle = 0.0  # slew, rad (positive: towards +z)
        self.rows = []  # (t, vx, vy, vz, wait, load or None)

    def row(self, v, wait=False, load=None):
        self.rows.append((self.t, v[0], v[1], v[2], 1 if wait else 0, load))

    def hold(self, seconds, wait=False, load=None):
        self.row((0.0, 0.0, 0.0), wait, load)
        self.t += seconds

    def move(self, radial_m_s, up_m_s, seconds):
        """Along the reach (out positive) and up, at the present slew angle."""
        c, s = math.cos(self.angle), math.sin(self.angle)
        self.row((radial_m_s * c, up_m_s, radial_m_s * s))
        self.t += seconds
        self.reach += radial_m_s * seconds

    def slew(self, degrees, tip_speed_m_s):
        """An arc at the present reach: degrees at the tip speed (positive: towards +z)."""
        total = math.radians(degrees)
        omega = math.copysign(tip_speed_m_s / self.reach, total)
        steps = max(1, round(abs(total / omega) / ROW_S))
        dt = abs(total / omega) / steps
        for _ in range(steps):
            mid = self.angle + 0.5 * omega * dt  # the row's direction at its middle
            v = omega * self.reach
            self.row((-v * math.sin(mid), 0.0, v * math.cos(mid)))
            self.t += dt
            self.angle += omega * dt

    def text(self, comment):
        lines = [f"# {line}".rstrip() for line in comment.strip().splitlines()]
        lines.append("# Written by tools/make_loading_cycles.py; docs/replay-format.md#waits.")
        lines.append("t,v_x,v_y,v_z,wait,load_kg")
        for t, vx, vy, vz, wait, load in self.rows:
            cells = [f"{t:.3f}"] + [f"{v:.4f}" if abs(v) > 5e-5 else "0" for v in (vx, vy, vz)]
            cells += [str(wait), "" if load is None else f"{load:g}"]
            lines.append(",".join(cells))
        return "\n".join(lines) + "\n"


def loading_cycle(log_reach_m, log_kg, bunk_reach_m, slew_deg=90.0, slew_speed=0.8):
    c = Cycle()
    c.hold(1.0, load=0)
    # Reach out over the log and lower onto it; let the grapple settle, grab.
    c.move(0.6, 0.0, (log_reach_m - c.reach) / 0.6)
    c.move(0.0, -0.4, 3.0)
    c.hold(0.5, wait=True)
    c.hold(1.0, load=log_kg)
    # Lift and pull in towards the bunk's reach, slew to the bunk, let it settle.
    pull = log_reach_m - bunk_reach_m
    lift_s = max(3.0, pull / 0.5)
    c.move(-pull / lift_s, 1.2 / lift_s, lift_s)
    c.slew(slew_deg, slew_speed)
    c.hold(0.5, wait=True)
    # Lower onto the bunk, release, rise and slew back over the start.
    c.move(0.0, -0.4, 1.0)
    c.hold(1.0, load=0)
    c.move(0.0, 0.4, 1.0)
    c.slew(-slew_deg, slew_speed)
    c.move((START_REACH_M - c.reach) / 2.0, -0.4, 2.0)
    c.hold(0.0)
    return c


CYCLES = {
    "near": (loading_cycle(5.5, 350, 5.0), """
A forestry loading cycle, a 350 kg log near the machine: reach out to 5.5 m, lower onto the log,
wait for the grapple to settle, grab, lift and pull in to 5.0 m, slew 90 degrees to the bunk at
0.8 m/s, wait, lower, release, rise and slew back. The log is not announced: the crane scale
weighs it (docs/loads.md)."""),
    "far": (loading_cycle(7.0, 400, 5.0), """
A forestry loading cycle, a 400 kg log at 7 m (84 % of the K70M's load chart there): reach out,
lower onto the log, wait for the grapple to settle, grab, lift and pull in to 5.0 m, slew 90
degrees to the bunk at 0.8 m/s, wait, lower, release, rise and slew back."""),
    "heavy": (loading_cycle(6.0, 700, 5.0), """
A forestry loading cycle with more than the crane may lift where it grabs: a 700 kg log at 6 m,
107 % of the K70M's load chart there. The rated capacity limiter trips at the grab (outward
motion refused); lifting and pulling in to 4.5 m stay free and bring the load moment back under
the chart, then the slew, the bunk and the way back as in the other cycles."""),
}


def main():
    outdir = sys.argv[1] if len(sys.argv) > 1 else os.path.join(
        os.path.dirname(os.path.abspath(__file__)), "..", "examples", "replays", "loading")
    os.makedirs(outdir, exist_ok=True)
    for name, (cycle, comment) in CYCLES.items():
        path = os.path.join(outdir, f"{name}.csv")
        with open(path, "w") as f:
            f.write(cycle.text(comment))
        print(f"wrote {path} ({len(cycle.rows)} rows, {cycle.t:.1f} s)")


if __name__ == "__main__":
    main()
