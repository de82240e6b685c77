#!/usr/bin/env python3
"""The panels of the shipped Foxglove layout (examples/foxglove/craneassist-layout.json), drawn
from a recording's channels (tools/foxglove/mcap_to_csv.mjs): the crane as /tf places its links
(side view), the pump's power and flow against their limits, the scale with the available tip
speed, and the active limit over time. Not a Foxglove screenshot: the same message paths, drawn
with matplotlib (docs/foxglove.md says why).

    plot_layout.py LAYOUT.csv OUT.png [TITLE]
"""
import csv
import math
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

rows = list(csv.DictReader(open(sys.argv[1])))
out = sys.argv[2]
title = sys.argv[3] if len(sys.argv) > 3 else ""


def col(name):
    return [float(r[name]) if r.get(name, "") not in ("", "null") else math.nan for r in rows]


t = col("t")
fig = plt.figure(figsize=(13, 7.5))
grid = fig.add_gridspec(4, 2, width_ratios=[1.0, 1.25], hspace=0.45, wspace=0.18)

# The 3-D panel's crane, from the side: reach (horizontal distance from the slew axis) and height.
ax = fig.add_subplot(grid[:, 0])
links = ["slew_link", "lift_link", "tilt_link", "extension_link", "tip_link"]
picks = [int(i * (len(rows) - 1) / 5) for i in range(6)]
for k, i in enumerate(picks):
    r = rows[i]
    pts = [(math.hypot(float(r[f"{l}_x"]), float(r[f"{l}_y"])), float(r[f"{l}_z"])) for l in links]
    shade = 0.25 + 0.6 * k / (len(picks) - 1)
    ax.plot([p[0] for p in pts], [p[1] for p in pts], "-o", color=(0.85 * shade, 0.55 * shade, 0.1),
            lw=3, ms=4, label=f"t = {t[i]:.1f} s")
ax.plot(col("tip_link_x") and [math.hypot(x, y) for x, y in zip(col("tip_link_x"), col("tip_link_y"))],
        col("tip_link_z"), ":", color="0.4", lw=1, label="tip path")
ax.set_aspect("equal")
ax.set_xlabel("reach from the slew axis (m)")
ax.set_ylabel("height above base_link (m)")
ax.set_title("3D: the URDF moved by /tf (side view)")
ax.legend(fontsize=8, loc="lower left")
ax.grid(alpha=0.3)


def plot(slot, series, ylabel, panel):
    a = fig.add_subplot(grid[slot, 1])
    for name, label, style in series:
        a.plot(t, col(name), style, label=label, lw=1.4)
    a.set_ylabel(ylabel)
    a.set_title(panel, fontsize=10)
    a.legend(fontsize=8, loc="upper right")
    a.grid(alpha=0.3)
    return a


plot(0, [("pump_power_w", "pump_power_w", "-"), ("ref_power_w", "ref_power_w (model)", "--"),
         ("power_limit_w", "power_limit_w", "k-")], "W",
     "/craneassist/hydraulics: pump power against the prime mover's limit")
plot(1, [("pump_flow_m3s", "pump_flow_m3s", "-"), ("flow_demand_m3s", "flow_demand_m3s (unscaled)", "--"),
         ("flow_limit_m3s", "flow_limit_m3s", "k-")], "m^3/s",
     "/craneassist/hydraulics: pump flow against its limit")
plot(2, [("scale", "limits.scale", "-"), ("avail_speed_m_s", "polytope.avail_speed_m_s (m/s)", "-")],
     "", "scale and the tip speed available along the stick")
a = fig.add_subplot(grid[3, 1])
limits = [r["active_limit"] for r in rows]
names = sorted(set(limits), key=limits.index)
colors = plt.cm.tab10.colors
for k, name in enumerate(names):
    spans, start = [], None
    for i, v in enumerate(limits + [None]):
        if v == name and start is None:
            start = i
        elif v != name and start is not None:
            spans.append((t[start], t[i - 1] - t[start] + 0.01))
            start = None
    a.broken_barh(spans, (0, 1), color=colors[k % 10], label=name)
a.set_yticks([])
a.set_xlabel("t (s)")
a.set_title("/craneassist/limits.active_limit (state transitions)", fontsize=10)
a.legend(fontsize=8, ncol=len(names), loc="upper right")
fig.suptitle(title + "\ndrawn from the MCAP recording's channels with the layout's message paths "
             "(not a Foxglove screenshot)", fontsize=10)
fig.savefig(out, dpi=90)
print(f"wrote {out}")
