#!/usr/bin/env python3
"""The hanging grapple's swing with and without sway damping (docs/sway.md): writes the replays,
runs each twice on the simulated K70M (`replay`, then `replay --no-sway-damping`), measures the
logs and prints one Markdown table. Standard library only (the plots need matplotlib).

  tools/sway_figures.py CRANEASSIST OUTDIR [--quick] [--check] [--plots DIR] [--jobs N]

Scenarios (crane frame: x out, y up, z across, i.e. a slew):
  stop    the stick pushed at V along one of the six axis directions for about 1 m (at least
          1.5 s), released (a step to zero), the run going on 6 s;
  turn    V along one axis for about 1 m (at least 1.5 s), turned by 90 deg to another, held
          3 s, released.
Speeds 0.3, 0.6 and 1.0 m/s; loads 0, 400 and 800 kg, unannounced (`--payload`), from the pose
INITIAL (4.0 m reach, where the chart rates 1260 kg; 1 m further out 880 kg). --quick: the
speeds 0.3 and 1.0, the loads 0 and 800 (the CI test).

Figures per run, each for the damped and the undamped run:
  peak        the largest |swing_deg| of the run;
  from +1 s   the largest |swing_deg| from 1 s after the stick stops (turns: after the turn,
              up to the release), the issue's measure of residual swing;
  at rest     the largest |swing_deg| once both runs' tips are at rest (below 0.01 m/s for the
              rest of the run), the swing the stop leaves behind;
  rest        when the tip came to rest, after the release;
  travel      the tip's path from the release to rest;
  dir err     the summary's steady direction error, commanded vs measured (max, deg);
  limits      the scaler's limits that acted on the way (`active_limit` other than none).
              Where the load limiter refuses the motion or a joint end brakes it, that stop is
              the limit's, not shaped: such runs are marked "stopped by a limit". (The pump's
              pressure or power and the speed caps take the reference over for a while; the
              damping starts again after them, and those runs are checked like the others.)
--check exits 1 unless every run that no limit stopped meets: swing left at rest at least 80 %
less than undamped (where undamped leaves at least 0.5 deg), the tip at rest at most 1 s later,
and the direction error at most 1 deg above the undamped run's.
"""
import argparse
import concurrent.futures
import csv
import math
import os
import re
import subprocess
import sys

REST_SPEED = 0.01  # m/s
AXES = {"out": (1, 0, 0), "in": (-1, 0, 0), "up": (0, 1, 0), "down": (0, -1, 0),
        "left": (0, 0, 1), "right": (0, 0, -1)}
TURNS = (("out", "left"), ("left", "in"), ("up", "right"))
SETTLE_S = 6.0
# The limits that stop the tip themselves, unshaped: the load limiter's refusal and the brake at a
# joint end (the pump's pressure and power and the speed caps take the reference over, and the
# damping starts again after them).
STOPPED_BY = {"joint_limit", "overload"}
INITIAL = "lift=35 deg, tilt=-110 deg, extension=1.8 m"
TURN_HOLD_S = 3.0


def scenarios(quick):
    speeds = (0.3, 1.0) if quick else (0.3, 0.6, 1.0)
    loads = (0, 800) if quick else (0, 400, 800)
    out = []
    for load in loads:
        for v in speeds:
            t = round(max(1.5, 1.0 / v), 2)  # about 1 m, at least 1.5 s
            for name, d in AXES.items():
                rows = [(0.0, [v * c for c in d]), (t, [0.0, 0.0, 0.0])]
                out.append({"name": f"stop-{name}-{v}-{load}kg", "kind": "stop", "rows": rows,
                            "release": t, "load": load, "v": v})
            for a, b in TURNS:
                rows = [(0.0, [v * c for c in AXES[a]]), (t, [v * c for c in AXES[b]]),
                        (t + TURN_HOLD_S, [0.0, 0.0, 0.0])]
                out.append({"name": f"turn-{a}-{b}-{v}-{load}kg", "kind": "turn", "rows": rows,
                            "turn": t, "release": t + TURN_HOLD_S, "load": load, "v": v})
    return out


def write_replay(path, rows):
    with open(path, "w") as f:
        f.write("t,v_x,v_y,v_z\n")
        for t, v in rows:
            f.write(f"{t},{v[0]},{v[1]},{v[2]}\n")


def run(binary, outdir, initial, sc, damped):
    tag = "damped" if damped else "undamped"
    replay = os.path.join(outdir, sc["name"] + ".csv")
    log = os.path.join(outdir, f"{sc['name']}-{tag}.log.csv")
    cmd = [binary, "replay", replay, "--settle", str(SETTLE_S), "--log", log,
           "--payload", str(sc["load"]), "--initial", initial]
    if not damped:
        cmd.append("--no-sway-damping")
    p = subprocess.run(cmd, capture_output=True, text=True)
    if p.returncode != 0:
        raise SystemExit(f"{' '.join(cmd)}: exit {p.returncode}\n{p.stdout}{p.stderr}")
    m = re.search(r"tip direction error, commanded vs measured .*?: max ([0-9.]+) deg", p.stdout)
    return log, float(m.group(1)) if m else float("nan")


def read_log(path):
    t, speed, swing, limits = [], [], [], set()
    with open(path, newline="") as f:
        for r in csv.DictReader(f):
            t.append(float(r["t"]))
            speed.append(math.hypot(float(r["tip_vx"]), float(r["tip_vy"]), float(r["tip_vz"])))
            swing.append(float(r["swing_deg"]) if r["swing_deg"] else float("nan"))
            if r["active_limit"] not in ("none", "stale_input"):
                limits.add(r["active_limit"])
    return t, speed, swing, limits


def rest_time(t, speed, after):
    """The time after `after` from which the tip stays below REST_SPEED."""
    last = after
    for ti, s in zip(t, speed):
        if ti >= after and s >= REST_SPEED:
            last = ti
    return last


def peak(t, swing, start, end=math.inf):
    vals = [abs(s) for ti, s in zip(t, swing) if start <= ti < end]
    return max(vals) if vals else 0.0


def measure(sc, logs):
    out = {}
    rests = {}
    data = {}
    for tag, (log, dir_err) in logs.items():
        t, speed, swing, limits = read_log(log)
        data[tag] = (t, swing)
        rests[tag] = rest_time(t, speed, sc["release"])
        if sc["kind"] == "stop":
            plus1 = peak(t, swing, sc["release"] + 1.0)
        else:
            plus1 = peak(t, swing, sc["turn"] + 1.0, sc["release"])
        travel = sum(s * (t[k + 1] - t[k]) for k, s in enumerate(speed[:-1])
                     if t[k] >= sc["release"])
        out[tag] = {"peak": peak(t, swing, 0.0), "plus1": plus1, "travel": travel,
                    "rest": rests[tag] - sc["release"], "dir_err": dir_err, "limits": limits}
    both = max(rests.values())
    for tag, (t, swing) in data.items():
        out[tag]["at_rest"] = peak(t, swing, both)
    return out


def reduction(damped, undamped):
    return 100.0 * (1.0 - damped / undamped) if undamped > 0 else float("nan")


def verdict(m):
    d, u = m["damped"], m["undamped"]
    problems = []
    if u["at_rest"] >= 0.5 and d["at_rest"] > 0.2 * u["at_rest"]:
        problems.append(f"left {d['at_rest']:.2f} deg at rest against {u['at_rest']:.2f}")
    if d["rest"] > u["rest"] + 1.0:
        problems.append(f"at rest {d['rest'] - u['rest']:.2f} s later")
    if d["dir_err"] > u["dir_err"] + 1.0:
        problems.append(f"direction error {d['dir_err']:.2f} deg against {u['dir_err']:.2f}")
    return problems


def plots(outdir, plotdir, names):
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    import craneassist_log
    plt = craneassist_log.pyplot()
    os.makedirs(plotdir, exist_ok=True)
    for name, title in names:
        fig, axes = plt.subplots(2, 1, figsize=(8, 5.5), sharex=True)
        for tag, style in (("undamped", "--"), ("damped", "-")):
            log = craneassist_log.load(os.path.join(outdir, f"{name}-{tag}.log.csv"))
            t = log["t"]
            speed = [math.hypot(a, b, c) for a, b, c in zip(log["tip_vx"], log["tip_vy"],
                                                            log["tip_vz"])]
            axes[0].plot(t, speed, style, label=f"tip speed, {tag}")
            axes[1].plot(t, log["swing_deg"], style, label=f"swing, {tag}")
        craneassist_log.label(axes[0], "m/s", title)
        craneassist_log.label(axes[1], "deg", "swing from the vertical", "t (s)")
        path = os.path.join(plotdir, f"sway_{name.split('-')[0]}.png")
        craneassist_log.save(fig, axes, path, 110, 8)
        print(f"wrote {path}")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("binary")
    ap.add_argument("outdir")
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--check", action="store_true")
    ap.add_argument("--plots")
    ap.add_argument("--jobs", type=int, default=os.cpu_count() or 1)
    ap.add_argument("--initial", default=INITIAL)
    args = ap.parse_args()
    os.makedirs(args.outdir, exist_ok=True)
    scs = scenarios(args.quick)
    for sc in scs:
        write_replay(os.path.join(args.outdir, sc["name"] + ".csv"), sc["rows"])
    jobs = [(sc, damped) for sc in scs for damped in (True, False)]
    with concurrent.futures.ThreadPoolExecutor(args.jobs) as pool:
        results = list(pool.map(lambda j: run(args.binary, args.outdir, args.initial, *j), jobs))
    logs = {}
    for (sc, damped), res in zip(jobs, results):
        logs.setdefault(sc["name"], {})["damped" if damped else "undamped"] = res
    print("| run | peak deg (undamped / damped) | from +1 s deg | reduction | left at rest deg "
          "| reduction | tip at rest s after release | travel m | dir err deg | limits |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    failed = taken_over = 0
    worst_plus1 = worst_rest = math.inf
    for sc in scs:
        m = measure(sc, logs[sc["name"]])
        d, u = m["damped"], m["undamped"]
        r1 = reduction(d["plus1"], u["plus1"])
        rr = reduction(d["at_rest"], u["at_rest"])
        problems = verdict(m)
        taken = bool(d["limits"] & STOPPED_BY)
        if taken:
            taken_over += 1
            problems = ["stopped by a limit"] + problems
        else:
            failed += bool(problems)
            worst_plus1 = min(worst_plus1, r1)
            if u["at_rest"] >= 0.5:
                worst_rest = min(worst_rest, rr)
        print(f"| {sc['name']} | {u['peak']:.2f} / {d['peak']:.2f} | {u['plus1']:.2f} / "
              f"{d['plus1']:.2f} | {r1:.0f} % | {u['at_rest']:.2f} / {d['at_rest']:.2f} | "
              f"{rr:.0f} % | {u['rest']:.2f} / {d['rest']:.2f} | {u['travel']:.2f} / "
              f"{d['travel']:.2f} | {u['dir_err']:.2f} / "
              f"{d['dir_err']:.2f} | {', '.join(sorted(d['limits'] | u['limits'])) or '-'} |" +
              (" **" + "; ".join(problems) + "**" if problems else ""))
    print(f"\n{len(scs)} runs, {taken_over} stopped by a limit; of the other "
          f"{len(scs) - taken_over}, {len(scs) - taken_over - failed} met the targets; least "
          f"reduction from +1 s {worst_plus1:.0f} %, of the swing left at rest (undamped 0.5 deg "
          f"or more) {worst_rest:.0f} %")
    if args.plots:
        plots(args.outdir, args.plots, [("stop-out-0.6-400kg", "a stop from 0.6 m/s out, 400 kg"),
                                        ("turn-out-left-0.6-400kg",
                                         "a 90 deg turn at 0.6 m/s, out to a slew, 400 kg")])
    if args.check:
        if failed:
            print(f"sway targets MISSED on {failed} runs")
            return 1
        print("sway targets met on every run that no limit stopped")
    return 0


if __name__ == "__main__":
    sys.exit(main())
