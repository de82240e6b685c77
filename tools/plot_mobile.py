#!/usr/bin/python3
"""Plots two `craneassist follow` logs side by side (docs/mobile.md): case 1 (flow bound only)
and case 2 (with tool-error scaling), as the paper's figure 6 does.

Rows: the platform and tool paths seen from above; the tool height against its reference; the
hub-motor flows and their sum against Q_max (with a shared pump, `--pump shared`, also the
crane's flow and the motors' and the crane's together); the tool error.

Usage: plot_mobile.py CASE1.csv CASE2.csv OUT.png
"""
import csv
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

LPM = 60000.0  # m^3/s -> L/min


def read(path):
    with open(path) as f:
        lines = f.readlines()
    rows = list(csv.DictReader(line for line in lines if not line.startswith("#")))
    cols = {k: [] for k in rows[0] if k != "limit"}
    for r in rows:
        for k in cols:
            cols[k].append(float(r[k]))
    cols["shared"] = any("--pump shared" in line for line in lines if line.startswith("#"))
    return cols


def main():
    if len(sys.argv) != 4:
        sys.exit(__doc__)
    logs = [read(sys.argv[1]), read(sys.argv[2])]
    titles = ["case 1: flow bound only", "case 2: flow bound and tool-error scaling"]
    if logs[0]["shared"]:
        titles = [t + ", shared pump" for t in titles]
    fig, axes = plt.subplots(4, 2, figsize=(12, 13), gridspec_kw={"height_ratios": [1.4, 1, 1, 1]})
    for c, (d, title) in enumerate(zip(logs, titles)):
        t = d["t"]
        ax = axes[0][c]
        ax.plot(d["tool_x_d"], d["tool_y_d"], "k-", lw=1, label="tool reference")
        ax.plot(d["tool_x"], d["tool_y"], "C1-", lw=1, label="tool")
        ax.plot(d["x_d"], d["y_d"], "k--", lw=1, label="platform reference (offset path)")
        ax.plot(d["x"], d["y"], "C0-", lw=1, label="platform")
        ax.plot(d["x"][0], d["y"][0], "C0o")
        ax.set_aspect("equal")
        ax.set_xlabel("x [m]")
        ax.set_ylabel("y [m]")
        ax.set_title(title)
        ax.legend(fontsize=7, loc="lower right")
        ax = axes[1][c]
        ax.plot(t, d["tool_z_d"], "k-", lw=1, label="reference (at the present s)")
        ax.plot(t, d["tool_z"], "C1-", lw=1, label="tool")
        ax.set_ylabel("tool height z [m]")
        ax.legend(fontsize=7)
        ax = axes[2][c]
        for i, name in enumerate(["fl", "fr", "rl", "rr"]):
            ax.plot(t, [q * LPM for q in d["flow_" + name]], lw=0.8, label=name)
        ax.plot(t, [q * LPM for q in d["flow_sum"]], "k-", lw=1.2, label="sum")
        if d["shared"]:
            ax.plot(t, [q * LPM for q in d["arm_flow"]], "C6-", lw=0.8, label="crane")
            total = [(a + b) * LPM for a, b in zip(d["flow_sum"], d["arm_flow"])]
            ax.plot(t, total, "C5-", lw=1.2, label="motors + crane")
        ax.plot(t, [q * LPM for q in d["flow_max"]], "r--", lw=1, label="Q_max")
        ax.set_ylabel("pump flow [L/min]" if d["shared"] else "hub-motor flow [L/min]")
        ax.legend(fontsize=7, ncol=3)
        ax = axes[3][c]
        ax.plot(t, d["tool_error"], "C3-", lw=1)
        ax.set_yscale("log")
        ax.set_ylim(1e-3, 3)
        ax.set_ylabel("tool error |e| [m]")
        ax.set_xlabel("t [s]")
        for row in axes[1:]:
            row[c].grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(sys.argv[3], dpi=90)


if __name__ == "__main__":
    main()
