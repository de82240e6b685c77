#!/usr/bin/python3
"""The crane scale and the rated capacity limiter of one run, from its per-cycle log
(docs/log-format.md, docs/loads.md):

  (a) the payload estimate against the simulated load over time, shaded where the tip moves
      (faster than 0.05 m/s), with the load chart's rated load at the tip's present reach;
  (b) the load moment ratio (estimate / rated load at the reach) with the warning (90 %) and
      overload (100 %) lines, and the cycles whose active limit is `overload` marked.

    build/app/craneassist replay examples/replays/work_cycle.csv --log run.csv
    tools/plot_loads.py run.csv loads.png
    tools/plot_loads.py run.csv loads.png --chart my_crane.yaml

--chart names the crane config whose `load_chart:` gives the rated load line of (a) (default the
K70M's, config/cranes/k70m.yaml; `--chart none` leaves the line out). Columns are read by name
from the header; a machine's log has an empty `load_kg` (no simulated truth), drawn as nothing.
Needs python3-matplotlib (Debian package).
"""
import argparse
import csv
import math
import os
import re
import sys

from craneassist_log import pyplot

MOVING_M_S = 0.05
WARNING = 0.9
OVERLOAD = 1.0
DEFAULT_CHART = os.path.normpath(
    os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "config", "cranes", "k70m.yaml"))
LENGTH_UNITS = {"m": 1.0, "cm": 1e-2, "mm": 1e-3}
MASS_UNITS = {"kg": 1.0}


def read_log(path):
    """{column: list} for the columns this figure needs: floats (NaN for an empty cell), the
    active limit as text. Lines starting with '#' are skipped."""
    need = ["t", "tip_x", "tip_z", "tip_vx", "tip_vy", "tip_vz", "load_kg", "payload_estimate_kg",
            "load_moment_ratio", "active_limit"]
    with open(path, newline="") as f:
        reader = csv.DictReader(line for line in f if not line.startswith("#"))
        missing = [c for c in need if c not in (reader.fieldnames or [])]
        if missing:
            raise SystemExit(f"{path}: no column {', '.join(missing)} (a log from before the crane "
                             "scale? docs/log-format.md)")
        rows = list(reader)
    if not rows:
        raise SystemExit(f"{path}: no rows")
    cols = {c: [float(r[c]) if r[c].strip() else math.nan for r in rows]
            for c in need if c != "active_limit"}
    cols["active_limit"] = [r["active_limit"] for r in rows]
    return cols


def chart_quantity(text, units, field, path):
    """The SI values of a config quantity "V1 V2 ... UNIT, SOURCE" (docs/config.md)."""
    value = text.split("#", 1)[0].split(",", 1)[0].strip()
    m = re.fullmatch(r"([-+0-9.eE\s]+?)\s*([A-Za-z]+)", value)
    if not m or m.group(2) not in units:
        raise SystemExit(f"{path}: load_chart.{field}: cannot read '{value}' "
                         f"(expected numbers and one of {', '.join(units)})")
    return [float(v) * units[m.group(2)] for v in m.group(1).split()]


def read_chart(path):
    """(reach in m, rated load in kg) from a crane config's `load_chart:`, or None without one.
    A line reader for this one section (the crane's parser checks the file: config.md)."""
    fields, inside = {}, False
    with open(path) as f:
        for line in f:
            if not line.strip() or line.lstrip().startswith("#"):
                continue
            if not line[0].isspace():
                inside = line.split("#", 1)[0].strip() == "load_chart:"
                continue
            if inside:
                key, _, rest = line.strip().partition(":")
                fields[key] = rest
    if "reach" not in fields or "rated_load" not in fields:
        return None
    reach = chart_quantity(fields["reach"], LENGTH_UNITS, "reach", path)
    rated = chart_quantity(fields["rated_load"], MASS_UNITS, "rated_load", path)
    if len(reach) != len(rated) or not reach:
        raise SystemExit(f"{path}: load_chart: {len(reach)} reaches but {len(rated)} rated loads")
    return reach, rated


def rated_at(chart, reach):
    """The rated load at a reach as the controller takes it (config::LoadChart::rated_kg_at):
    linear between the points, the first inside the first, the last load moment held beyond."""
    rs, ms = chart
    if reach <= rs[0]:
        return ms[0]
    if reach >= rs[-1]:
        return ms[-1] * rs[-1] / reach
    k = next(i for i in range(1, len(rs)) if rs[i] >= reach)
    w = (reach - rs[k - 1]) / (rs[k] - rs[k - 1])
    return ms[k - 1] + w * (ms[k] - ms[k - 1])


def check_chart(log, rated, path):
    """Warns when the log's load moment was taken against another chart than --chart's (the run
    used another config, or a binary built before the config was edited): the log's own rated
    load is estimate / ratio."""
    for k, (m, r) in enumerate(zip(log["payload_estimate_kg"], log["load_moment_ratio"])):
        if m > 10.0 and r > 0.0 and abs(m / r - rated[k]) > 0.01 * rated[k]:
            print(f"plot_loads.py: warning: at t = {log['t'][k]:g} s the log's rated load is "
                  f"{m / r:.1f} kg, {os.path.relpath(path)}'s chart gives {rated[k]:.1f} kg: "
                  "was the run made with another chart? (--chart CONFIG)", file=sys.stderr)
            return


def spans(t, flags):
    """(start, end) time intervals over which flags holds, each cycle taken to last until the
    next one's time."""
    out, start = [], None
    for k, f in enumerate(flags):
        if f and start is None:
            start = t[k]
        if not f and start is not None:
            out.append((start, t[k]))
            start = None
    if start is not None:
        out.append((start, t[-1] + (t[-1] - t[-2] if len(t) > 1 else 0.01)))
    return out


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("log", help="a craneassist per-cycle CSV log (--log)")
    p.add_argument("out", help="the PNG to write")
    p.add_argument("--chart", default=DEFAULT_CHART,
                   help="the crane config with the load chart (default: the K70M's); "
                   "none: no chart line")
    p.add_argument("--title", default=None, help="a title (default: the log's name)")
    a = p.parse_args()
    log = read_log(a.log)
    chart = None if a.chart == "none" else read_chart(a.chart)
    t = log["t"]
    n = len(t)
    speed = [math.sqrt(log["tip_vx"][k] ** 2 + log["tip_vy"][k] ** 2 + log["tip_vz"][k] ** 2)
             for k in range(n)]
    moving = spans(t, [v > MOVING_M_S for v in speed])
    overload = [s == "overload" for s in log["active_limit"]]

    try:
        plt = pyplot()
    except ImportError:
        raise SystemExit("plot_loads.py needs python3-matplotlib (apt-get install python3-matplotlib)")
    fig, (mass, ratio) = plt.subplots(2, 1, figsize=(11, 7.5), sharex=True, constrained_layout=True)
    fig.suptitle(a.title or a.log)

    # (a) The crane scale against the simulated load.
    for k, (t0, t1) in enumerate(moving):
        mass.axvspan(t0, t1, color="0.9", label=f"tip moving (> {MOVING_M_S} m/s)" if k == 0 else None)
    truth = log["load_kg"]
    estimate = log["payload_estimate_kg"]
    rated = []
    if chart:
        rated = [rated_at(chart, math.hypot(log["tip_x"][k], log["tip_z"][k])) for k in range(n)]
        check_chart(log, rated, a.chart)
        mass.plot(t, rated, color="tab:red", linestyle=":", linewidth=1.2,
                  label="rated load at the reach (chart)")
    if any(not math.isnan(v) for v in truth):
        mass.step(t, truth, where="post", color="black", linestyle="--", linewidth=1.2,
                  label="simulated load")
    mass.plot(t, estimate, color="tab:blue", linewidth=1.2, label="crane scale estimate")
    # Room for the loads and the rated line, unless the chart's loads near the pillar would
    # squash a small load (then the rated line shows where it is lowest).
    base = max([v for v in truth + estimate if not math.isnan(v)] + [min(rated, default=0.0), 1.0])
    top = max(base, min(max(rated, default=0.0), 2.5 * base))
    mass.set_ylim(-0.05 * top, 1.25 * top)
    title = f"Payload: estimate at the end {estimate[-1]:.1f} kg"
    if not math.isnan(truth[-1]):
        title += f", simulated {truth[-1]:.1f} kg"
    mass.set_title(title)
    mass.set_ylabel("mass [kg]")
    mass.legend(loc="best", fontsize=8)
    mass.grid(True, alpha=0.3)

    # (b) The load moment against the chart.
    pct = [100.0 * r for r in log["load_moment_ratio"]]
    count = sum(overload)
    for k, (t0, t1) in enumerate(spans(t, overload)):
        ratio.axvspan(t0, t1, color="tab:red", alpha=0.2,
                      label=f"active limit overload ({count} cycles)" if k == 0 else None)
    ratio.plot(t, pct, color="tab:purple", linewidth=1.5, label="load moment / chart", zorder=3)
    ratio.axhline(100 * WARNING, color="tab:orange", linestyle="--", linewidth=1,
                  label=f"warning {100 * WARNING:.0f} %")
    ratio.axhline(100 * OVERLOAD, color="tab:red", linestyle="-", linewidth=1,
                  label=f"overload {100 * OVERLOAD:.0f} %")
    peak = max(pct) if pct else 0.0
    ratio.set_ylim(0, max(110.0, 1.1 * peak))
    ratio.set_title(f"Load moment: peak {peak:.0f} % of the chart, at or above the warning in "
                    f"{sum(r >= 100 * WARNING for r in pct)} cycles, active limit overload in {count}")
    ratio.set_ylabel("load moment [% of chart]")
    ratio.set_xlabel("t [s]")
    ratio.legend(loc="best", fontsize=8)
    ratio.grid(True, alpha=0.3)

    fig.savefig(a.out, dpi=110)
    print(f"wrote {a.out}")


if __name__ == "__main__":
    main()
