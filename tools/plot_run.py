#!/usr/bin/python3
"""The standard figures of one run, from its per-cycle log (docs/log-format.md):

  1. the tip path, seen from above and from the side;
  2. speed: the operator's command, the scaled reference and the measured tip speed, with the
     direction error between command and measured motion;
  3. the pump: power and flow against their limits;
  4. the scaling's active limit and scale over time.

    build/app/craneassist replay examples/replays/heavy_lift.csv --payload 650 --log run.csv
    tools/plot_run.py run.csv run.png
    tools/plot_run.py live.csv live.png --max-power-kw 35 --max-flow-lpm 325

The limits default to the K70M reference crane's (config/cranes/k70m.yaml: 35 kW prime mover,
325 L/min pump); give another crane's with --max-power-kw and --max-flow-lpm. The direction
error is taken over every cycle where both the command and the measured tip speed are above
0.05 m/s (the summary of `craneassist replay` also waits for the command to be steady for 0.5 s,
so its figure leaves out the turns). Needs python3-matplotlib (Debian package).
"""
import argparse
import math

from craneassist_log import load, pyplot

MOVING_M_S = 0.05


def norm3(log, prefix, k):
    return math.sqrt(sum(log[f"{prefix}{a}"][k] ** 2 for a in ("x", "y", "z")))


def direction_error_deg(log, k):
    """Angle between the command and the measured tip velocity, or None when either is slow."""
    c = [log[f"cmd_v{a}"][k] for a in "xyz"]
    m = [log[f"tip_v{a}"][k] for a in "xyz"]
    nc, nm = math.sqrt(sum(v * v for v in c)), math.sqrt(sum(v * v for v in m))
    if nc < MOVING_M_S or nm < MOVING_M_S:
        return None
    cos = sum(a * b for a, b in zip(c, m)) / (nc * nm)
    return math.degrees(math.acos(max(-1.0, min(1.0, cos))))


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("log", help="a craneassist per-cycle CSV log (--log)")
    p.add_argument("out", help="the PNG to write")
    p.add_argument("--max-power-kw", type=float, default=35.0, help="the power limit (default 35)")
    p.add_argument("--max-flow-lpm", type=float, default=325.0, help="the flow limit (default 325)")
    p.add_argument("--title", default=None, help="a title (default: the log's name)")
    a = p.parse_args()
    log = load(a.log)
    t = log["t"]
    n = len(t)

    plt = pyplot()
    fig = plt.figure(figsize=(11, 12), constrained_layout=True)
    grid = fig.add_gridspec(4, 2, height_ratios=[1.3, 1, 1, 0.8])
    top, side = fig.add_subplot(grid[0, 0]), fig.add_subplot(grid[0, 1])
    speed = fig.add_subplot(grid[1, :])
    pump = fig.add_subplot(grid[2, :], sharex=speed)
    limit = fig.add_subplot(grid[3, :], sharex=speed)
    fig.suptitle(a.title or a.log)

    # 1. The tip path.
    top.plot(log["tip_x"], log["tip_z"], color="tab:blue")
    top.plot(log["tip_x"][0], log["tip_z"][0], "o", color="tab:green", label="start")
    top.plot(log["tip_x"][-1], log["tip_z"][-1], "s", color="tab:red", label="end")
    top.set_xlabel("x forward [m]")
    top.set_ylabel("z lateral [m]")
    top.set_title("Tip path from above")
    top.set_aspect("equal", adjustable="datalim")
    top.legend(loc="best")
    side.plot(log["tip_x"], log["tip_y"], color="tab:blue")
    side.plot(log["tip_x"][0], log["tip_y"][0], "o", color="tab:green")
    side.plot(log["tip_x"][-1], log["tip_y"][-1], "s", color="tab:red")
    side.set_xlabel("x forward [m]")
    side.set_ylabel("y up [m]")
    side.set_title("Tip path from the side")
    side.set_aspect("equal", adjustable="datalim")

    # 2. Speeds and direction error.
    speed.plot(t, [norm3(log, "cmd_v", k) for k in range(n)], color="0.55", label="command")
    speed.plot(t, [norm3(log, "ref_v", k) for k in range(n)], color="tab:orange", label="scaled reference")
    speed.plot(t, [norm3(log, "tip_v", k) for k in range(n)], color="tab:blue", label="measured tip")
    speed.set_ylabel("tip speed [m/s]")
    err = [direction_error_deg(log, k) for k in range(n)]
    moving = [e for e in err if e is not None]
    ax_err = speed.twinx()
    ax_err.plot(t, [e if e is not None else float("nan") for e in err], color="tab:red", linewidth=0.8,
                label="direction error")
    ax_err.set_ylabel("direction error [deg]", color="tab:red")
    title = "Speed and direction"
    if moving:
        rms = math.sqrt(sum(e * e for e in moving) / len(moving))
        title += f": direction error max {max(moving):.2f} deg, rms {rms:.2f} deg over {len(moving)} moving cycles"
    speed.set_title(title)
    speed.legend(loc="upper left")

    # 3. The pump against its limits.
    pump.plot(t, [w / 1e3 for w in log["pump_power_w"]], color="tab:orange", label="power")
    pump.axhline(a.max_power_kw, color="tab:orange", linestyle=":", label=f"power limit {a.max_power_kw:g} kW")
    pump.set_ylabel("pump power [kW]")
    ax_flow = pump.twinx()
    ax_flow.plot(t, [q * 6e4 for q in log["pump_flow_m3s"]], color="tab:blue", label="flow")
    ax_flow.axhline(a.max_flow_lpm, color="tab:blue", linestyle=":", label=f"flow limit {a.max_flow_lpm:g} L/min")
    ax_flow.set_ylabel("pump flow [L/min]", color="tab:blue")
    ax_flow.set_ylim(0, a.max_flow_lpm * 1.1)
    pump.set_ylim(0, a.max_power_kw * 1.1)
    peak_p, peak_q = max(log["pump_power_w"]) / 1e3, max(log["pump_flow_m3s"]) * 6e4
    energy = log["energy_j"][-1] / 1e3
    pump.set_title(f"Pump: peak {peak_p:.1f} kW, peak {peak_q:.0f} L/min, energy {energy:.1f} kJ")
    lines = pump.get_legend_handles_labels()
    more = ax_flow.get_legend_handles_labels()
    pump.legend(lines[0] + more[0], lines[1] + more[1], loc="upper left")

    # 4. What limits the motion.
    names = sorted(set(log["active_limit"]), key=lambda s: (s != "none", s))
    level = {name: i for i, name in enumerate(names)}
    limit.step(t, [level[s] for s in log["active_limit"]], where="post", color="tab:purple")
    limit.set_yticks(range(len(names)), names)
    limit.set_ylabel("active limit")
    ax_scale = limit.twinx()
    ax_scale.plot(t, log["scale"], color="tab:green", linewidth=0.8)
    ax_scale.set_ylabel("scale", color="tab:green")
    ax_scale.set_ylim(0, 1.05)
    limit.set_xlabel("t [s]")
    counts = {name: log["active_limit"].count(name) for name in names}
    limit.set_title("Active limit (cycles: " + ", ".join(f"{k} {v}" for k, v in counts.items()) + ") and scale")

    fig.savefig(a.out, dpi=110)
    print(f"wrote {a.out}")


if __name__ == "__main__":
    main()
