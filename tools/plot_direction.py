#!/usr/bin/python3
"""Plot what flow prescaling does on a saturating move, from two craneassist logs.

    craneassist replay examples/replays/combined_move.csv --pump-max-flow "100 L/min" \
        --prime-mover-power "200 kW" --log scaled.csv
    craneassist replay examples/replays/combined_move.csv --pump-max-flow "100 L/min" \
        --prime-mover-power "200 kW" --no-scaling --log unscaled.csv
    tools/plot_direction.py unscaled.csv scaled.csv docs/img/combined_move.png

Needs python3-matplotlib (Debian package).
"""
import csv
import math
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def load(path):
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    cols = {k: [float(r[k]) for r in rows] for k in rows[0] if k not in ("active_limit", "pump_limit")}
    cols["pump_limit"] = [r["pump_limit"] for r in rows]
    return cols


def direction_error(c):
    out = []
    for i in range(len(c["t"])):
        cmd = [c["cmd_vx"][i], c["cmd_vy"][i], c["cmd_vz"][i]]
        tip = [c["tip_vx"][i], c["tip_vy"][i], c["tip_vz"][i]]
        ncmd, ntip = math.sqrt(sum(x * x for x in cmd)), math.sqrt(sum(x * x for x in tip))
        if ncmd == 0 or ntip < 0.05:
            out.append(float("nan"))
            continue
        dot = sum(a * b for a, b in zip(cmd, tip)) / (ncmd * ntip)
        out.append(math.degrees(math.acos(max(-1.0, min(1.0, dot)))))
    return out


def main():
    if len(sys.argv) != 4:
        sys.exit(__doc__)
    unscaled, scaled, out = load(sys.argv[1]), load(sys.argv[2]), sys.argv[3]
    fig = plt.figure(figsize=(8, 8.5))
    ax = [fig.add_subplot(3, 1, 1)]
    ax.append(fig.add_subplot(3, 1, 2))
    ax.append(fig.add_subplot(3, 1, 3, sharex=ax[1]))
    for c, name, style in ((unscaled, "no scaling", "tab:red"), (scaled, "flow prescaling", "tab:blue")):
        ax[0].plot(c["tip_z"], c["tip_y"], color=style, label=name)
        ax[1].plot(c["t"], direction_error(c), color=style, label=name)
        ax[2].plot(c["t"], [q * 60e3 for q in c["pump_flow_m3s"]], color=style, label=name)
    ax[0].set_xlabel("lateral tip position z [m]")
    ax[0].set_title("Tip path seen from the front (commanded: straight, up and sideways)")
    ax[0].set_ylabel("tip height y [m]")
    ax[1].set_ylabel("direction error [deg]")
    ax[1].set_title("Angle between commanded and measured tip velocity")
    ax[2].set_ylabel("pump flow [L/min]")
    ax[2].set_xlabel("time [s]")
    ax[2].set_title("Pump flow (limit 100 L/min)")
    for a in ax:
        a.grid(True, alpha=0.3)
        a.legend(loc="upper right")
    fig.tight_layout()
    fig.savefig(out, dpi=110)


if __name__ == "__main__":
    main()
