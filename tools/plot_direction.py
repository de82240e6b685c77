#!/usr/bin/python3
"""Plot a baseline run against a scaled run of the same replay, from two craneassist logs:
the tip path seen from the front, the direction error, pump flow and pump power.

    craneassist replay examples/replays/combined_move.csv --pump-max-flow "100 L/min" \\
        --prime-mover-power "200 kW" --scaling none --log unscaled.csv
    craneassist replay examples/replays/combined_move.csv --pump-max-flow "100 L/min" \\
        --prime-mover-power "200 kW" --scaling flow --log scaled.csv
    tools/plot_direction.py unscaled.csv scaled.csv docs/img/combined_move.png \\
        --labels "no scaling" "flow prescaling" --flow-limit 100

Needs python3-matplotlib (Debian package).
"""
import argparse
import math

from craneassist_log import label, load, pyplot, save

plt = pyplot()


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
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("baseline")
    parser.add_argument("scaled")
    parser.add_argument("output")
    parser.add_argument("--labels", nargs=2, default=["no scaling", "flow prescaling"])
    parser.add_argument("--flow-limit", type=float, help="pump flow limit to draw, L/min")
    parser.add_argument("--power-limit", type=float, help="prime-mover power to draw, kW")
    args = parser.parse_args()
    runs = ((load(args.baseline), args.labels[0], "tab:red"),
            (load(args.scaled), args.labels[1], "tab:blue"))

    fig = plt.figure(figsize=(8, 11))
    ax = [fig.add_subplot(4, 1, 1)]
    for i in range(2, 5):
        ax.append(fig.add_subplot(4, 1, i, sharex=ax[1] if i > 2 else None))
    for c, name, color in runs:
        ax[0].plot(c["tip_z"], c["tip_y"], color=color, label=name)
        ax[1].plot(c["t"], direction_error(c), color=color, label=name)
        ax[2].plot(c["t"], [q * 60e3 for q in c["pump_flow_m3s"]], color=color, label=name)
        ax[3].plot(c["t"], [p / 1e3 for p in c["pump_power_w"]], color=color, label=name)
    if args.flow_limit:
        ax[2].axhline(args.flow_limit, color="black", linestyle=":", label="pump maximum")
    if args.power_limit:
        ax[3].axhline(args.power_limit, color="black", linestyle=":", label="P_max")
    label(ax[0], "tip height y [m]",
          "Tip path seen from the front (the command is a straight line)",
          xlabel="lateral tip position z [m]")
    label(ax[1], "direction error [deg]",
          "Angle between commanded and measured tip velocity (tip faster than 0.05 m/s)")
    label(ax[2], "pump flow [L/min]", "Pump flow")
    label(ax[3], "pump power [kW]", "Pump power", xlabel="time [s]")
    save(fig, ax, args.output, dpi=100, legend_fontsize=8)


if __name__ == "__main__":
    main()
