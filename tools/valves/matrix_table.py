#!/usr/bin/env python3
"""The robustness matrix as a Markdown table: per machine variant, the worst figures over the
suite's runs (direction error p95 and max, lateral speed over 50 ms on the one-line runs, stall
events, stops still moving at neutral, runs that met every target), uncalibrated and calibrated.
Usage: matrix_table.py UNCALIBRATED.csv CALIBRATED.csv (from craneassist suite --matrix)."""
import csv
import sys


def worst(path):
    rows = {}
    order = []
    with open(path, newline="") as f:
        for r in csv.DictReader(f):
            v = r["variant"]
            if v not in rows:
                order.append(v)
                rows[v] = {"p95": 0.0, "max": 0.0, "lat": 0.0, "stalls": 0, "timeouts": 0,
                           "runs": 0, "ok": 0, "worst_run": ""}
            w = rows[v]
            p95 = float(r["direction_p95_deg"])
            if p95 >= w["p95"]:
                w["p95"], w["worst_run"] = p95, r["run"]
            w["max"] = max(w["max"], float(r["direction_max_deg"]))
            if r["lateral_peak_m_s"]:
                w["lat"] = max(w["lat"], float(r["lateral_peak_m_s"]))
            w["stalls"] += int(r["stall_events"])
            w["timeouts"] += int(r["stop_timeouts"])
            w["runs"] += 1
            w["ok"] += int(r["missed"]) == 0
    return order, rows


def main():
    order, before = worst(sys.argv[1])
    _, after = worst(sys.argv[2])
    print("| machine | uncalibrated: p95 / max deg | lateral m/s | stalls | stops moving | runs ok "
          "| calibrated: p95 / max deg | lateral m/s | stalls | stops moving | runs ok |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    for v in order:
        cells = [v]
        for side in (before, after):
            w = side.get(v)
            if w is None:
                cells += ["-"] * 5
                continue
            cells += [f"{w['p95']:.2f} / {w['max']:.1f}", f"{w['lat']:.3f}", str(w["stalls"]),
                      str(w["timeouts"]), f"{w['ok']}/{w['runs']}"]
        print("| " + " | ".join(cells) + " |")
    # The worst variant uncalibrated: the highest p95, and the run it comes from.
    name = max(order, key=lambda v: before[v]["p95"])
    print(f"\nWorst uncalibrated: {name} (p95 {before[name]['p95']:.2f} deg on "
          f"{before[name]['worst_run']}).")


if __name__ == "__main__":
    main()
