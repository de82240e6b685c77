#!/usr/bin/python3
"""Energy table and bar chart of `craneassist energy` results (docs/energy.md).

usage: energy_report.py RESULTS.csv DOC.md CHART.png

Replaces the part of DOC.md between the markers
  <!-- energy-results:begin --> and <!-- energy-results:end -->
with tables of the simulator-measured pump energy, and draws CHART.png.
"""
import csv
import sys
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

METHODS = ["pinv-joint", "pinv-actuator", "min-flow", "min-ls-power",
           "dp-ls", "dp-cp", "dp-actuator-energy", "dp-extension"]
PSEUDO_INVERSES = ["pinv-joint", "pinv-actuator"]
ENERGY_OPTIMAL = {"ls": ["min-ls-power", "dp-ls"], "cp": ["min-flow", "dp-cp"]}
PATHS = ["horizontal", "vertical", "half_cycle"]
STARTS = ["shortest", "middle"]
BEGIN, END = "<!-- energy-results:begin -->", "<!-- energy-results:end -->"


def load(path):
    runs = {}
    with open(path, newline="") as f:
        for r in csv.DictReader(f):
            key = (r["path"], r["start"], r["method"], r["system"])
            runs[key] = r
    return runs


def kj(r):
    return float(r["energy_j"]) / 1e3


def tables(runs):
    out = []
    ratios = defaultdict(list)
    for path in PATHS:
        for start in STARTS:
            if (path, start, "dp-ls", "ls") not in runs:
                continue
            out.append(f"**{path.replace('_', '-')}, {start} feasible extension at the start**\n")
            out.append("| resolution | LS energy [kJ] | vs best LS | CP energy [kJ] | vs best CP "
                       "| model LS [kJ] | tip error max [mm] | plan within limits |")
            out.append("|---|---:|---:|---:|---:|---:|---:|---|")
            # The best energy-optimal resolution whose plan keeps every cylinder limit (all of
            # them when none does).
            best = {}
            for system in ("ls", "cp"):
                candidates = [runs[(path, start, m, system)] for m in ENERGY_OPTIMAL[system]]
                within = [r for r in candidates if int(r["penalised_stages"]) == 0]
                best[system] = min(kj(r) for r in (within or candidates))
            for m in METHODS:
                ls, cp = runs[(path, start, m, "ls")], runs[(path, start, m, "cp")]
                ok = "yes" if int(ls["penalised_stages"]) == 0 else \
                    f"no ({ls['penalised_stages']} stages)"
                out.append(
                    f"| {m} | {kj(ls):.1f} | {kj(ls) / best['ls']:.2f} | {kj(cp):.1f} "
                    f"| {kj(cp) / best['cp']:.2f} | {float(ls['model_energy_j']) / 1e3:.1f} "
                    f"| {float(ls['max_tip_error_m']) * 1e3:.1f} | {ok} |")
                if m in PSEUDO_INVERSES and int(ls["penalised_stages"]) == 0:
                    for system, r in (("ls", ls), ("cp", cp)):
                        ratios[(m, system)].append(kj(r) / best[system])
            out.append("")
    summary = ["| pseudo-inverse | system | energy over the best energy-optimal resolution "
               "(cases within limits) |", "|---|---|---|"]
    for m in PSEUDO_INVERSES:
        for system in ("ls", "cp"):
            v = ratios[(m, system)]
            if v:
                summary.append(f"| {m} | {system.upper()} | {min(v):.2f} to {max(v):.2f}, "
                               f"mean {sum(v) / len(v):.2f} ({len(v)} cases) |")
    return "\n".join(summary) + "\n\n" + "\n".join(out)


def chart(runs, png):
    fig, axes = plt.subplots(len(STARTS), len(PATHS), figsize=(15, 8), sharey=False)
    colors = {"ls": "#1f77b4", "cp": "#ff7f0e"}
    for i, start in enumerate(STARTS):
        for j, path in enumerate(PATHS):
            ax = axes[i][j]
            xs = range(len(METHODS))
            for k, system in enumerate(("ls", "cp")):
                vals = [kj(runs[(path, start, m, system)]) if (path, start, m, system) in runs
                        else 0.0 for m in METHODS]
                bars = ax.bar([x + (k - 0.5) * 0.4 for x in xs], vals, width=0.4,
                              color=colors[system], label=f"{system.upper()} system")
                for bar, m in zip(bars, METHODS):  # hatched: the plan violates a cylinder limit
                    r = runs.get((path, start, m, system))
                    if r is not None and int(r["penalised_stages"]) > 0:
                        bar.set_hatch("///")
                        bar.set_alpha(0.5)
            ax.set_xticks(list(xs))
            ax.set_xticklabels(METHODS, rotation=50, ha="right", fontsize=8)
            ax.set_title(f"{path.replace('_', '-')}, {start} start", fontsize=10)
            ax.set_ylabel("pump energy [kJ]")
            ax.grid(axis="y", alpha=0.3)
            if i == 0 and j == 0:
                ax.legend(fontsize=8)
    fig.suptitle("Simulator-measured pump energy per redundancy resolution "
                 "(K70M, no payload; CP at 20 MPa; hatched: the plan violates a cylinder limit)")
    fig.tight_layout()
    fig.savefig(png, dpi=90)


def main():
    if len(sys.argv) != 4:
        sys.exit(__doc__)
    results, doc, png = sys.argv[1:]
    runs = load(results)
    chart(runs, png)
    text = open(doc).read()
    if BEGIN not in text or END not in text:
        sys.exit(f"{doc}: missing the markers {BEGIN} and {END}")
    head, rest = text.split(BEGIN, 1)
    _, tail = rest.split(END, 1)
    open(doc, "w").write(head + BEGIN + "\n" + tables(runs) + END + tail)
    print(f"wrote {doc} and {png}")


if __name__ == "__main__":
    main()
