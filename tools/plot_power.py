#!/usr/bin/python3
"""Plot two craneassist logs of the same path under different power bounds.

The 2R experiment of docs/scaling.md:
    craneassist research experiment-2r --power-bound actuator_sum --log old.csv
    craneassist research experiment-2r --power-bound load_sensing --log ls.csv
    tools/plot_power.py old.csv ls.csv 8000 docs/img/scaling_2r.png

Arguments: the baseline log, the load-sensing log, P_max in W, the output PNG.
Needs python3-matplotlib (Debian package).
"""
import sys

from craneassist_log import label, load, pyplot, save

plt = pyplot()


def main():
    if len(sys.argv) != 5:
        sys.exit(__doc__)
    old, ls, p_max, out = load(sys.argv[1]), load(sys.argv[2]), float(sys.argv[3]), sys.argv[4]
    runs = ((old, "sum-of-actuator-powers bound (baseline)", "tab:red"),
            (ls, "load-sensing bound", "tab:blue"))
    fig, ax = plt.subplots(4, 1, figsize=(8, 10), sharex=True)
    for c, name, color in runs:
        ax[0].plot(c["t"], [p / 1e3 for p in c["pump_power_w"]], color=color, label=name)
        ax[1].plot(c["t"], c["sdot"], color=color, label=name)
        ax[2].plot(c["t"], c["q1_ref"], color=color, label=f"q1, {name}")
        ax[2].plot(c["t"], c["q2_ref"], color=color, linestyle="--", label=f"q2, {name}")
    ax[0].axhline(p_max / 1e3, color="black", linestyle=":", label="P_max")
    label(ax[0], "pump power [kW]", "Power measured at the simulated load-sensing pump")
    label(ax[1], "path speed sdot [1/s]", "Path speed after scaling")
    label(ax[2], "joint reference [rad]", "Joint references f(s)")
    ax[3].plot(ls["t"], ls["sddot"], color="tab:blue", label="sddot (load-sensing bound)")
    ax[3].plot(ls["t"], ls["sddot_max"], color="tab:green", linewidth=0.8, label="upper bound")
    ax[3].plot(ls["t"], ls["sddot_min"], color="tab:purple", linewidth=0.8, label="lower bound")
    lo = min(ls["sddot"]) - 1.0
    hi = max(ls["sddot"]) + 1.0
    ax[3].set_ylim(lo, hi)
    label(ax[3], "path acceleration [1/s^2]",
          "Path acceleration and its power bounds (load-sensing run)", xlabel="time [s]")
    save(fig, ax, out, dpi=110, legend_fontsize=7)


if __name__ == "__main__":
    main()
