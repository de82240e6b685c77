#!/usr/bin/python3
"""Plot two craneassist logs of the same path under different power bounds.

The 2R experiment of docs/scaling.md:
    craneassist experiment-2r --power-bound actuator_sum --log old.csv
    craneassist experiment-2r --power-bound load_sensing --log ls.csv
    tools/plot_power.py old.csv ls.csv 8000 docs/img/scaling_2r.png

Arguments: the baseline log, the load-sensing log, P_max in W, the output PNG.
Needs python3-matplotlib (Debian package).
"""
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from craneassist_log import load  # noqa: E402


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
    ax[0].set_ylabel("pump power [kW]")
    ax[0].set_title("Power measured at the simulated load-sensing pump")
    ax[1].set_ylabel("path speed sdot [1/s]")
    ax[1].set_title("Path speed after scaling")
    ax[2].set_ylabel("joint reference [rad]")
    ax[2].set_title("Joint references f(s)")
    ax[3].plot(ls["t"], ls["sddot"], color="tab:blue", label="sddot (load-sensing bound)")
    ax[3].plot(ls["t"], ls["sddot_max"], color="tab:green", linewidth=0.8, label="upper bound")
    ax[3].plot(ls["t"], ls["sddot_min"], color="tab:purple", linewidth=0.8, label="lower bound")
    lo = min(ls["sddot"]) - 1.0
    hi = max(ls["sddot"]) + 1.0
    ax[3].set_ylim(lo, hi)
    ax[3].set_ylabel("path acceleration [1/s^2]")
    ax[3].set_xlabel("time [s]")
    ax[3].set_title("Path acceleration and its power bounds (load-sensing run)")
    for a in ax:
        a.grid(True, alpha=0.3)
        a.legend(loc="upper right", fontsize=7)
    fig.tight_layout()
    fig.savefig(out, dpi=110)


if __name__ == "__main__":
    main()
