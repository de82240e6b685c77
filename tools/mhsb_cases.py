#!/usr/bin/python3
"""Runs paper 001's cases (its Table 2, sections 3.1-3.4 and 4.2) with `craneassist ptp` on the
MHSB three-link arm and writes one row per run to a CSV (docs/data/mhsb_cases.csv), the table of
docs/mhsb.md#the-papers-results-compared, plus each run's files (trajectory, S2 path, simulator
log) in a work directory for tools/plot_mhsb.py. Run through tools/make_mhsb_figures.sh.

Every figure comes from the binary's output; the paper's own figures, for the side-by-side
columns, are those printed in its text (paper_* columns, empty where it gives none).
"""
import argparse
import csv
import math
import os
import re
import subprocess
import sys
import time

CONFIG = os.path.relpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "config",
                                      "cranes", "mhsb_3link.yaml"))

# Table 2: start, goal, weights. Case 2-2 and 3-2 change only the goal (2-2 also keeps 2-1's
# start), Cases 4-x share the points.
CASE1 = ((0.55, -0.05), (0.55, 0.6))
CASE2_1 = ((0.55, 0.6), (0.55, -0.05))
CASE2_2 = ((0.55, 0.6), (0.55, -0.6))
CASE3_1 = ((0.55, -0.7), (0.55, 0.75))
CASE3_2 = ((0.55, -0.7), (0.75, 0.55))
CASE4 = ((0.5, -0.15), (0.65, 0.45))
W11 = (0.5, 0, 2)
W12 = (0, 15, 2)
# Each case planned with the series circuit's energy (ptp's default) and with the paper's eq. 9
# as printed (the "-paper" rows: the paper's own figures are its planner's): suffix, options, words.
ENERGY_MODELS = (("", [], ""), ("-paper", ["--energy-model", "paper"], ", paper's eq. 9"))

# The conventional method's held J3 (the paper's [18], Cases 4-2 and 4-3: 70 and 130 deg; our
# optimal table has J3 positive at Case 4's start, as the paper's).
CASE4_J3_DEG = (70.0, 130.0)

FIELDS = [
    "case", "group", "description", "from_x_m", "from_z_m", "to_x_m", "to_z_m", "w1", "w2", "w3",
    "options", "s2_nodes", "s2_length_m", "s2_time_s", "s2_energy_j", "s2_switches", "time_s",
    "energy_j", "length_m", "switches", "peak_speed_ratio", "s2_mean_area_m2_s2",
    "s2_mean_n_area_m2_s2", "goal_n_area_m2_s2", "planning_ms", "s2_modes",
    "sim_energy_j", "sim_planned_j", "sim_main_j", "sim_servo_pump_j", "sim_max_error_deg",
    "sim_max_p_supply_mpa", "paper_time_s", "paper_energy_j", "paper_s2_energy_j",
    "paper_max_error_deg", "note",
]


def parse(text):
    """The figures of one `ptp` run's standard output."""
    r = {}
    m = re.search(r"S2 path: (\d+) nodes, ([\d.]+) m, ([\d.]+) s, ([\d.]+) J, (\d+) mode switches",
                  text)
    if m:
        r.update(s2_nodes=m[1], s2_length_m=m[2], s2_time_s=m[3], s2_energy_j=m[4],
                 s2_switches=m[5])
    m = re.search(r"S3/S4 trajectory: ([\d.]+) s, ([\d.]+) J, tip path ([\d.]+) m, (\d+) mode "
                  r"switches, peak cylinder speed ([\d.]+) V_L", text)
    if m:
        r.update(time_s=m[1], energy_j=m[2], length_m=m[3], switches=m[4], peak_speed_ratio=m[5])
    m = re.search(r"planning time \(S2-S4\): ([\d.]+) ms", text)
    if m:
        r["planning_ms"] = m[1]
    m = re.search(r"S2 modes: (.*)", text)
    if m:
        r["s2_modes"] = m[1].strip()
    m = re.search(r"energy measured ([\d.]+) J \(main pump ([\d.]+), servo-pumps ([\d.]+)\) "
                  r"against ([\d.]+) J planned", text)
    if m:
        r.update(sim_energy_j=m[1], sim_main_j=m[2], sim_servo_pump_j=m[3], sim_planned_j=m[4])
    m = re.search(r"largest joint error, deg: (.*) \(", text)
    if m:
        r["sim_max_error_deg"] = "%.2f" % max(float(x.split()[-1]) for x in m[1].split(","))
    m = re.search(r"highest supply pressure, MPa: (.*)", text)
    if m:
        r["sim_max_p_supply_mpa"] = "%.1f" % max(float(x.split()[-1]) for x in m[1].split(","))
    return r


class Runner:
    def __init__(self, args):
        self.bin = args.bin
        self.work = args.work
        self.grid = args.grid
        self.table = args.table
        self.rows = []
        os.makedirs(self.work, exist_ok=True)

    def ptp(self, case, group, description, points, weights, options=(), simulate=False,
            config=CONFIG, files=True, paper=(None, None, None), note="", extra=(),
            paper_error=None):
        (fx, fz), (tx, tz) = points
        cmd = [self.bin, "research", "ptp", "--config", config, "--from", f"{fx},{fz}", "--to", f"{tx},{tz}",
               "--weights", ",".join(str(w) for w in weights), *options]
        if self.grid:
            cmd += ["--grid", self.grid]
        if self.table and config == CONFIG and not any("fixed-last" in o for o in options):
            cmd += ["--table", self.table]
        stem = os.path.join(self.work, case)
        if files:
            cmd += ["-o", stem + ".traj.csv", "--path-out", stem + ".path.csv"]
        if simulate:
            cmd += ["--simulate", *extra]
        if case.startswith("4-"):
            cmd += ["--workspace-out", stem + ".workspace.csv"]
        t0 = time.time()
        out = subprocess.run(cmd, capture_output=True, text=True)
        if out.returncode != 0:
            sys.exit(f"mhsb_cases: {' '.join(cmd)} failed ({out.returncode}):\n{out.stderr}")
        with open(stem + ".out.txt", "w") as f:
            f.write(out.stdout)
        row = dict(case=case, group=group, description=description, from_x_m=fx, from_z_m=fz,
                   to_x_m=tx, to_z_m=tz, w1=weights[0], w2=weights[1], w3=weights[2],
                   options=" ".join(o for o in options if not o.startswith(self.work)),
                   paper_time_s=paper[0] or "", paper_energy_j=paper[1] or "",
                   paper_s2_energy_j=paper[2] or "", paper_max_error_deg=paper_error or "",
                   note=note)
        row.update(parse(out.stdout))
        if files:
            # The mean flow manipulability polytope area over the S2 path's postures (Case 4).
            with open(stem + ".path.csv") as f:
                nodes = list(csv.DictReader(line for line in f if not line.startswith("#")))
            row["s2_mean_area_m2_s2"] = "%.3f" % (
                sum(float(n["area_m2_s2"]) for n in nodes) / len(nodes))
            if case.startswith("4-"):
                # The all-N polytope of the postures along the path and at the goal (the paper's
                # Figure 9 compares them): the same pattern for every method.
                with open(stem + ".workspace.csv") as f:
                    grid = {(r["x_m"], r["z_m"]): float(r["area_m2_s2"]) for r in csv.DictReader(
                        line for line in f if not line.startswith("#"))}
                areas = [grid[(n["x_m"], n["z_m"])] for n in nodes]
                row["s2_mean_n_area_m2_s2"] = "%.3f" % (sum(areas) / len(areas))
                row["goal_n_area_m2_s2"] = "%.3f" % areas[-1]
        self.rows.append(row)
        print(f"  {case:>14}: S2 {row.get('s2_energy_j')} J {row.get('s2_time_s')} s; S3/S4 "
              f"{row.get('energy_j')} J {row.get('time_s')} s; simulated "
              f"{row.get('sim_energy_j', '-')} J ({time.time() - t0:.1f} s)", flush=True)
        return out.stdout

    def write(self, file):
        os.makedirs(os.path.dirname(file) or ".", exist_ok=True)
        with open(file, "w", newline="") as f:
            f.write("# paper 001's cases with craneassist ptp on config/cranes/mhsb_3link.yaml "
                    "(tools/make_mhsb_figures.sh, docs/mhsb.md); s2_*: the discrete path, "
                    "time_s/energy_j/length_m: the S3/S4 trajectory (planned), sim_*: the MHSB "
                    "simulator's run of it; paper_*: the paper's text\n")
            w = csv.DictWriter(f, fieldnames=FIELDS)
            w.writeheader()
            for r in self.rows:
                w.writerow(r)


def variant_config(work, name, substitutions):
    """A copy of the arm's config in WORK with each (old line text, new text) substituted once
    (the sensitivity runs: another P0, leakage, torque arms or Table 3's specifications)."""
    with open(CONFIG) as f:
        text = f.read()
    for old, new in substitutions:
        text, n = re.subn(re.escape(old), lambda _m: new, text)
        assert n == 1, f"the config's '{old}' line changed"
    path = os.path.join(work, f"mhsb_3link_{name}.yaml")
    with open(path, "w") as f:
        f.write(text)
    return path


P0_LINE = "supply_pressure: 4.0 MPa, paper"
LEAK_LINE = "leakage: 0.015 L/min, derived"


def p0_config(work, p0_mpa):
    """Section 3.4's variation of the main-pump pressure."""
    return variant_config(work, f"p0_{p0_mpa:g}", [(P0_LINE, f"supply_pressure: {p0_mpa} MPa, paper")])


def leakage_config(work, leak_lpm):
    """Another servo-valve leakage than the data sheet's (what the leakage changes)."""
    return variant_config(work, f"leak_{leak_lpm:g}", [(LEAK_LINE, f"leakage: {leak_lpm} L/min, assumed")])


def table3_config(work):
    """Paper 001's Table 3 (the specifications of its section 4 simulation): the main pump at
    5.5 MPa, the micro-pump's 0.54 L/min, and the boost its servo-motor's 0.427 N m gives on the
    0.18 cm^3 micro-pump (2 pi T / D = 14.9 MPa; still capped by the 14 MPa relief). The
    servo-valve's 6.9 L/min is the config's own."""
    return variant_config(work, "table3", [
        (P0_LINE, "supply_pressure: 5.5 MPa, paper  # Table 3"),
        ("servo_pump_max_flow: 0.2415 L/min, derived",
         "servo_pump_max_flow: 0.54 L/min, paper  # Table 3 (micro-pump)"),
        ("max_boost: 10 MPa, assumed", "max_boost: 14.9 MPa, derived  # Table 3: 2 pi 0.427 N m / 0.18 cm^3")])


def linkage_config(work, beta, p0_mpa=None):
    """The paper's joints are driven through four-bar linkages whose dimensions it does not give;
    the config has a constant torque arm r0 per joint. This copy gives each joint a torque arm
    that varies over its range as a linkage's does, r(q) = r0 (1 - beta ((q - qc) / h)^2) (qc the
    range's middle, h its half-width; beta 0.5: the arm falls to half at both ends, -0.5: it
    grows by half), the cylinder length its integral (a cubic, the config's polynomial linkage)
    and the stroke what the range needs; with P0_MPA also another main-pump pressure."""
    with open(CONFIG) as f:
        text = f.read()
    subs = []
    for block in text.split("\n  - name: ")[1:]:
        if "linkage: constant_arm" not in block:
            continue  # a body, or a joint without a constant arm
        m = re.search(r"(linkage: constant_arm\n\s+arm: ([\d.]+) mm[^\n]*\n\s+"
                      r"length_at_zero: ([\d.]+) mm[^\n]*)", block)
        q_min = math.radians(float(re.search(r"min: (-?[\d.]+) deg", block)[1]))
        q_max = math.radians(float(re.search(r"max: (-?[\d.]+) deg", block)[1]))
        r0, c0 = float(m[2]) / 1000.0, float(m[3]) / 1000.0
        qc, h = (q_min + q_max) / 2.0, (q_max - q_min) / 2.0
        k = r0 * beta / (3.0 * h * h)
        coeffs = [-k, 3.0 * k * qc, r0 - 3.0 * k * qc * qc, c0 + k * qc ** 3]
        lengths = [sum(a * q ** (3 - i) for i, a in enumerate(coeffs))
                   for q in (q_min + (q_max - q_min) * s / 64.0 for s in range(65))]
        indent = re.search(r"\n(\s+)arm:", m[1])[1]
        subs.append((m[1], f"linkage: polynomial\n{indent}coefficients: "
                     f"{' '.join('%.9g' % a for a in coeffs)} m, assumed  # beta {beta:g}"))
        stroke = re.search(r"stroke: [\d.]+ mm, assumed[^\n]*", block)[0]
        subs.append((stroke, f"stroke: {(max(lengths) - min(lengths)) * 1000.0 + 0.5:.1f} mm, assumed"))
    name = f"linkage_{beta:g}"
    if p0_mpa is not None:
        subs.append((P0_LINE, f"supply_pressure: {p0_mpa} MPa, paper"))
        name += f"_p0_{p0_mpa:g}"
    return variant_config(work, name, subs)


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--bin", default="build/app/craneassist")
    ap.add_argument("--work", required=True, help="directory for the runs' files")
    ap.add_argument("--out", required=True, help="the results CSV")
    ap.add_argument("--grid", help="grid spacing (default: ptp's, 5 cm)")
    ap.add_argument("--table", help="posture table file (default: ptp's cache)")
    ap.add_argument("--quick", action="store_true",
                    help="Case 1 and one Case 4 run only, no simulation (the plot smoke test)")
    args = ap.parse_args()
    r = Runner(args)
    sim = not args.quick

    print("Case 1: vertical lifting (energy-optimal, shortest time)")
    r.ptp("1-1", "1", "energy-optimal", CASE1, W11, simulate=sim, paper=(7.96, 532, 552))
    r.ptp("1-2", "1", "shortest time", CASE1, W12, simulate=sim, paper=(6.74, 698, None))
    if not args.quick:
        r.ptp("1-1-paper", "1", "energy-optimal, paper's eq. 9", CASE1, W11,
              ["--energy-model", "paper"], simulate=sim, paper=(7.96, 532, 552))
        r.ptp("1-2-paper", "1", "shortest time, paper's eq. 9", CASE1, W12,
              ["--energy-model", "paper"], simulate=sim, paper=(6.74, 698, None))
        print("Cases 2 and 3: unloading, full range")
        r.ptp("2-1", "2", "unloading", CASE2_1, W11, simulate=sim)
        for suffix, options, what in ENERGY_MODELS:
            r.ptp("2-2" + suffix, "2", "unloading, far" + what, CASE2_2, W11, options,
                  simulate=sim, paper=(8.0, 589, 576))
            r.ptp("3-1" + suffix, "3", "full range" + what, CASE3_1, W11, options, simulate=sim,
                  paper=(13.0, 989, None))
            r.ptp("3-2" + suffix, "3", "full range, outwards" + what, CASE3_2, W11, options,
                  simulate=sim, paper=(9.02, 1059, None))
        # What eq. 9 charges the paper's 3-2 route: the quickest plan, boosted from the start.
        r.ptp("3-2-paper-quick", "3q", "full range, outwards, shortest time, paper's eq. 9",
              CASE3_2, W12, ["--energy-model", "paper"], files=False)
    print("Case 4: the optimal posture table against the conventional fixed-J3 method")
    for suffix, model, what in ENERGY_MODELS:
        if suffix and args.quick:
            break
        r.ptp("4-1" + suffix, "4", "proposed (posture table)" + what, CASE4, W11, model,
              simulate=sim, paper=(None, 593, None))
        j3s = CASE4_J3_DEG[:1] if args.quick else CASE4_J3_DEG
        for i, (j3, paper) in enumerate(zip(j3s, (501, 742))):
            r.ptp(f"4-{i + 2}" + suffix, "4", f"fixed J3 {j3:g} deg" + what, CASE4, W11,
                  ["--posture", f"fixed-last:{j3:g}", *model], simulate=sim,
                  paper=(None, paper, None))
    if not args.quick:
        # The optimal table's posture jumps (docs/mhsb.md#the-dearest-steps): the same S1 with
        # ptp's continuity tie-break, postures within 15 % of the largest area kept near their
        # neighbours'.
        r.ptp("4-1-paper-cont", "4c", "proposed, continuity tie-break 0.15, paper's eq. 9", CASE4,
              W11, ["--continuity-tolerance", "0.15", "--energy-model", "paper"],
              paper=(None, 593, None))
        print("Case 5: weights, V_L, w3, P0")
        for w1 in (0, 0.01, 0.1):
            for w2 in (0, 1.3, 13):
                r.ptp(f"5-w{w1:g}-{w2:g}", "5w", "weight sweep (Figure 10), S2", CASE1, (w1, w2, 0),
                      files=False)
        for vl in range(6, 31, 2):
            r.ptp(f"5-vl{vl}", "5v", "V_L sweep on Case 1-2", CASE1, W12,
                  ["--velocity-limit", f"{vl} mm/s"], files=False)
        for w3 in range(0, 21, 2):
            r.ptp(f"5-w3-{w3}", "5s", "w3 sweep on Case 1-2", CASE1, (0, 15, w3), files=False)
        for p0, paper in ((2.5, 1054), (10, 1011)):
            cfg = p0_config(args.work, p0)
            r.ptp(f"5-p0-{p0:g}", "5p", f"P0 {p0:g} MPa on Case 1-1", CASE1, W11,
                  config=cfg, simulate=sim, paper=(None, paper, None))
            r.ptp(f"5-p0-{p0:g}-paper", "5p", f"P0 {p0:g} MPa on Case 1-1, paper's eq. 9", CASE1,
                  W11, ["--energy-model", "paper"], config=cfg, simulate=sim,
                  paper=(None, paper, None))
        for leak in (0, 0.25):
            cfg = leakage_config(args.work, leak)
            r.ptp(f"5-leak{leak:g}-1", "5l", f"leakage {leak:g} L/min, Case 1-1", CASE1, W11,
                  config=cfg, simulate=sim, paper=(7.96, 532, 552))
            r.ptp(f"5-leak{leak:g}-2", "5l", f"leakage {leak:g} L/min, Case 1-2", CASE1, W12,
                  config=cfg, simulate=sim, paper=(6.74, 698, None))
        for beta in (0.5, -0.5):
            cfg = linkage_config(args.work, beta)
            r.ptp(f"5-arm{beta:g}-1", "5a", f"torque arm beta {beta:g}, Case 1-1", CASE1, W11,
                  config=cfg, simulate=sim, paper=(7.96, 532, 552))
            r.ptp(f"5-arm{beta:g}-2", "5a", f"torque arm beta {beta:g}, Case 1-2", CASE1, W12,
                  config=cfg, simulate=sim, paper=(6.74, 698, None))
        # The main-pump trend on an arm whose torque arms grow towards the range ends (eq. 9).
        for p0, paper in ((2.5, 1054), (4.0, 532), (10, 1011)):
            r.ptp(f"5-arm-0.5-p0-{p0:g}-paper", "5ap",
                  f"torque arm beta -0.5, P0 {p0:g} MPa on Case 1-1, paper's eq. 9", CASE1, W11,
                  ["--energy-model", "paper"], config=linkage_config(args.work, -0.5, p0),
                  files=False, paper=(None, paper, None))
        print("Section 4.2: the moving goal")
        r.ptp("4.2", "goal", "moving goal, Table 1's P0 and Table 2's servo-pump flow",
              ((0.7, 0.5), (0.6, 0.2)), W11, simulate=True, paper_error=2.43,
              extra=["--goal-at", "3:0.8,0.2", "--goal-at", "6:0.6,0.5", "--sim-log",
                     os.path.join(args.work, "4.2.sim.csv")])
        r.ptp("4.2-t3", "goal", "moving goal, Table 3 (the paper's section 4 setup)",
              ((0.7, 0.5), (0.6, 0.2)), W11, config=table3_config(args.work), simulate=True,
              paper_error=2.43,
              extra=["--goal-at", "3:0.8,0.2", "--goal-at", "6:0.6,0.5", "--sim-log",
                     os.path.join(args.work, "4.2-t3.sim.csv")])
    # The mode regions (Figure 5) from the optimal table.
    cmd = [args.bin, "research", "ptp", "--config", CONFIG, "--from", "0.55,-0.05", "--to", "0.55,0.6",
           "--workspace-out", os.path.join(args.work, "workspace.csv")]
    if args.grid:
        cmd += ["--grid", args.grid]
    if args.table:
        cmd += ["--table", args.table]
    subprocess.run(cmd, check=True, capture_output=True)
    r.write(args.out)
    print(f"wrote {args.out} ({len(r.rows)} runs)")


if __name__ == "__main__":
    main()
