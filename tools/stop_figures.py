#!/usr/bin/env python3
"""How the crane stops at the end of a run: the replay files and the figures of
tools/stop_figures.sh (which runs the scenarios). Standard library only.

  tools/stop_figures.py cut [--stop-hold 4] [--hold-after 60] SRC.csv T PREFIX [SRC T PREFIX ...]
      Cuts each replay SRC.csv at T s, while the stick is still pushed, and writes
        PREFIX-end.csv   the rows before T and a row at T holding the same command
                         (the file, and so a `replay --settle 0` run, ends at T);
        PREFIX-stop.csv  the same rows, then a stop row at T and a last stop row at
                         T + stop-hold (the operator input not valid from T on);
        PREFIX-hold.csv  the same rows, then the command still held at T + hold-after
                         (for a run ended from outside, e.g. by SIGINT).
  tools/stop_figures.py report MANIFEST.tsv [--out FILE.md]
      Measures every run of the manifest (tab-separated, header
      motion, label, cut_s, ending, log, console, rc) and prints one Markdown table.

The stop of a run is the last stretch of rows whose `status` is not `running`, to the end of
the log (a `sim` run also starts with a deadman hold, not running, which is not the stop). A log
without a `status` column (an older binary) gets it inferred: not running where a `cmd_*` column
is nan or `active_limit` is `stale_input`, `stopped` where, besides, every spool is exactly 0.
"""
import argparse
import csv
import math
import os
import re
import sys

REST_SPEED = 0.01  # m/s: the tip is at rest below this
FULL_OPENING = 0.99  # |spool| at or above this: a fully open valve
COMMAND_SPOOL = 0.53  # |spool| above this before the stop: the section was commanded
STEADY_WINDOW = 0.5  # s before the stop for the steady load pressure
ENDINGS = ("replay end", "stop row", "deadman release", "SIGINT")
# Exit codes accepted per ending: timeout(1) gives 124 when it sent the signal.
ACCEPTED_RC = {"SIGINT": {0, 124, 130}}


class LogError(Exception):
    pass


# --------------------------------------------------------------------------- replay cutting

REPLAY_HEADERS = {
    ("t", "v_x", "v_y", "v_z"),
    ("t", "v_x", "v_y", "v_z", "stop"),
    ("t", "v_x", "v_y", "v_z", "load_kg"),
    ("t", "v_x", "v_y", "v_z", "stop", "load_kg"),
}


def read_replay(path):
    """Returns (columns, rows): rows as dicts of the cells as text (stripped)."""
    try:
        with open(path, encoding="utf-8-sig") as f:
            lines = f.read().splitlines()
    except OSError as e:
        raise SystemExit(f"{path}: cannot read the replay: {e.strerror}")
    columns, rows = None, []
    for n, line in enumerate(lines, 1):
        s = line.strip()
        if not s or s.startswith("#"):
            continue
        cells = [c.strip() for c in line.split(",")]
        if columns is None:
            columns = tuple(cells)
            if columns not in REPLAY_HEADERS:
                raise SystemExit(f"{path}:{n}: not a replay header (docs/replay-format.md): {s}")
            continue
        if len(cells) != len(columns):
            raise SystemExit(f"{path}:{n}: expected {len(columns)} fields, got {len(cells)}")
        row = dict(zip(columns, cells))
        try:
            row["_t"] = float(row["t"])
        except ValueError:
            raise SystemExit(f"{path}:{n}: field 't': not a number: {row['t']!r}")
        rows.append(row)
    if columns is None or not rows:
        raise SystemExit(f"{path}: no replay rows")
    return columns, rows


def fmt_t(t):
    return f"{t:.6g}"


def write_replay(path, columns, rows, comment):
    with open(path, "w") as f:
        for line in comment:
            f.write(f"# {line}\n")
        f.write(",".join(columns) + "\n")
        for r in rows:
            f.write(",".join(r.get(c, "") for c in columns) + "\n")


def cut(args):
    if not args.spec or len(args.spec) % 3:
        raise SystemExit("stop_figures.py cut: expected SRC T PREFIX triples")
    for src, t, prefix in zip(*[iter(args.spec)] * 3):
        try:
            t = float(t)
        except ValueError:
            raise SystemExit(f"stop_figures.py cut: {src}: cut time not a number: {t!r}")
        cut_one(src, t, prefix, args.stop_hold, args.hold_after)


def cut_one(src_path, T, prefix, stop_hold, hold_after):
    columns, rows = read_replay(src_path)
    before = [r for r in rows if r["_t"] < T]
    if not before:
        raise SystemExit(f"{src_path}: no row before the cut time {T} s")
    last = before[-1]
    if last.get("stop", "0") == "1":
        raise SystemExit(f"{src_path}: the command at {T} s is a stop row: cut it elsewhere")
    cmd = {c: last[c] for c in ("v_x", "v_y", "v_z")}
    if all(float(v) == 0.0 for v in cmd.values()):
        print(f"stop_figures.py: warning: {src_path}: the command at {T} s is zero",
              file=sys.stderr)
    has_load = "load_kg" in columns
    held = dict(cmd, t=fmt_t(T), stop="0")
    if has_load:
        held["load_kg"] = ""
    common = [f"Generated by tools/stop_figures.py from {src_path}: its rows before "
              f"t = {fmt_t(T)} s",
              f"and a row at {fmt_t(T)} s holding the command (v_x,v_y,v_z) = "
              f"({cmd['v_x']},{cmd['v_y']},{cmd['v_z']}) m/s."]

    write_replay(f"{prefix}-end.csv", columns, before + [held],
                 common + ["The file ends there, with the stick still pushed."])

    stop_cols = ("t", "v_x", "v_y", "v_z", "stop") + (("load_kg",) if has_load else ())
    zero = {"v_x": "0", "v_y": "0", "v_z": "0", "stop": "1"}
    stop_rows = [dict(r, stop=r.get("stop", "0")) for r in before] + [
        dict(zero, t=fmt_t(T)), dict(zero, t=fmt_t(T + stop_hold))]
    write_replay(f"{prefix}-stop.csv", stop_cols, stop_rows,
                 common[:1] + [f"then a stop row (input not valid) at {fmt_t(T)} s and a last "
                               f"stop row at {fmt_t(T + stop_hold)} s."])

    hold_rows = before + [held, dict(held, t=fmt_t(T + hold_after))]
    write_replay(f"{prefix}-hold.csv", columns, hold_rows,
                 common + [f"and again at {fmt_t(T + hold_after)} s: the run does not end "
                           f"by itself (it is ended from outside, SIGINT)."])


# --------------------------------------------------------------------------- log analysis

def read_log(path):
    """Returns (header, rows as lists of text cells)."""
    if not os.path.exists(path):
        raise LogError(f"{path}: log not written (file missing)")
    try:
        with open(path, newline="") as f:
            reader = csv.reader(line for line in f if not line.startswith("#"))
            header = next(reader, None)
            rows = [r for r in reader if r]
    except OSError as e:
        raise LogError(f"{path}: cannot read the log: {e.strerror}")
    except csv.Error as e:
        raise LogError(f"{path}: not a CSV log: {e}")
    if not header:
        raise LogError(f"{path}: empty log (no header)")
    if not rows:
        raise LogError(f"{path}: empty log (a header but no rows)")
    header = [h.strip() for h in header]
    for i, r in enumerate(rows):
        if len(r) != len(header):
            raise LogError(f"{path}: row {i + 2} has {len(r)} fields, the header {len(header)} "
                           f"(a truncated log?)")
    return header, rows


def numbered(header, prefix, suffix=""):
    names, i = [], 1
    while f"{prefix}{i}{suffix}" in header:
        names.append(f"{prefix}{i}{suffix}")
        i += 1
    return names


def analyse(path):
    header, rows = read_log(path)
    spools = numbered(header, "spool")
    ploads = numbered(header, "p_load", "_pa")
    needed = ["t", "tip_vx", "tip_vy", "tip_vz"]
    have_status = "status" in header
    if not have_status:
        needed += ["cmd_vx", "cmd_vy", "cmd_vz", "active_limit"]
    missing = [c for c in needed if c not in header]
    if not spools:
        missing.append("spool1..spooln")
    if not ploads:
        missing.append("p_load1_pa..p_loadn_pa")
    elif len(ploads) != len(spools):
        missing.append(f"p_load{len(ploads) + 1}_pa (the log has {len(spools)} spool columns)")
    if missing:
        raise LogError(f"{path}: missing column(s) {', '.join(missing)} "
                       f"(docs/log-format.md; the log has {len(header)} columns)")
    col = {h: i for i, h in enumerate(header)}

    def num(r, k, name):
        try:
            return float(r[col[name]])
        except ValueError:
            raise LogError(f"{path}: row {k + 2}, column {name}: not a number: "
                           f"{r[col[name]]!r}")

    t = [num(r, k, "t") for k, r in enumerate(rows)]
    spool = [[num(r, k, s) for s in spools] for k, r in enumerate(rows)]
    pload = [[num(r, k, p) for p in ploads] for k, r in enumerate(rows)]
    speed = [math.sqrt(sum(num(r, k, c) ** 2 for c in ("tip_vx", "tip_vy", "tip_vz")))
             for k, r in enumerate(rows)]

    if have_status:
        status = [r[col["status"]].strip() for r in rows]
        bad = sorted({s for s in status if s not in ("running", "stopping", "stopped")})
        if bad:
            raise LogError(f"{path}: unknown status value(s) {', '.join(bad)}")
    else:
        status = []
        for k, r in enumerate(rows):
            cmd_nan = any(math.isnan(num(r, k, c)) for c in ("cmd_vx", "cmd_vy", "cmd_vz"))
            if not (cmd_nan or r[col["active_limit"]].strip() == "stale_input"):
                status.append("running")
            elif all(s == 0.0 for s in spool[k]):
                status.append("stopped")
            else:
                status.append("stopping")

    running = [k for k, s in enumerate(status) if s == "running"]
    if not running:
        raise LogError(f"{path}: no `running` row: the crane never ran")
    if running[-1] == len(rows) - 1:
        raise LogError(f"{path}: the last row is `running`: the log has no stop at its end")
    k0 = running[-1] + 1  # the stop: k0 .. end
    t0 = t[k0]
    stop_rows = range(k0, len(rows))
    m = {"stop_t": t0, "start_speed": speed[k0 - 1], "status_inferred": not have_status}

    # a. peak spool step per cycle (into and during the stop).
    m["spool_step"] = max(abs(spool[k][i] - spool[k - 1][i])
                          for k in stop_rows if k > 0 for i in range(len(spools)))
    # b. full-opening reversals against each section's last command before the stop.
    last_sign = []
    for i in range(len(spools)):
        sign = 0
        for k in range(k0 - 1, -1, -1):
            if abs(spool[k][i]) > COMMAND_SPOOL:
                sign = 1 if spool[k][i] > 0 else -1
                break
        last_sign.append(sign)
    m["reversals"] = sum(1 for k in stop_rows for i in range(len(spools))
                         if last_sign[i] != 0 and abs(spool[k][i]) >= FULL_OPENING
                         and spool[k][i] * last_sign[i] < 0)
    m["reversal_sections"] = sorted({i + 1 for k in stop_rows for i in range(len(spools))
                                     if last_sign[i] != 0 and abs(spool[k][i]) >= FULL_OPENING
                                     and spool[k][i] * last_sign[i] < 0})
    # c. load pressures: peak during the stop, the mean over the last 0.5 s before it.
    m["p_peak"] = max(abs(p) for k in stop_rows for p in pload[k]) / 1e6
    steady = [k for k in range(k0) if t[k] >= t0 - STEADY_WINDOW - 1e-9]
    m["p_steady"] = (max(abs(sum(pload[k][i] for k in steady) / len(steady))
                         for i in range(len(ploads))) / 1e6) if steady else None
    # d, f. the first `stopped` row.
    ks = next((k for k in stop_rows if status[k] == "stopped"), None)
    m["stopped_speed"] = speed[ks] if ks is not None else None
    m["stop_time"] = t[ks] - t0 if ks is not None else None
    # e. time to rest.
    if speed[-1] >= REST_SPEED:
        m["rest_time"], m["end_speed"] = None, speed[-1]
    else:
        j = len(rows) - 1
        while j > k0 and speed[j - 1] < REST_SPEED:
            j -= 1
        m["rest_time"], m["end_speed"] = t[j] - t0, speed[-1]
    return m


def read_console(path):
    """The run's summary: the count of real-time overruns, if it prints one."""
    try:
        with open(path, errors="replace") as f:
            text = f.read()
    except OSError:
        return None, ""
    mo = re.search(r"(\d+) overruns", text)
    return (int(mo.group(1)) if mo else None), text


def f3(x):
    return "–" if x is None else f"{x:.3f}"


def report(args):
    try:
        with open(args.manifest, newline="") as f:
            runs = list(csv.DictReader(f, delimiter="\t"))
    except OSError as e:
        raise SystemExit(f"{args.manifest}: cannot read the manifest: {e.strerror}")
    need = {"motion", "label", "cut_s", "ending", "log", "console", "rc"}
    if not runs or not need <= set(runs[0]):
        raise SystemExit(f"{args.manifest}: not a manifest (header: {' '.join(sorted(need))})")

    errors, results = [], []
    for run in runs:
        rc = int(run["rc"])
        res = {"run": run, "m": None}
        overruns, console = read_console(run["console"])
        res["overruns"] = overruns
        if rc not in ACCEPTED_RC.get(run["ending"], {0}):
            tail = " | ".join(console.strip().splitlines()[-3:])
            errors.append(f"{run['log']}: {run['motion']} / {run['ending']}: the binary exited "
                          f"with {rc} (console {run['console']}: {tail})")
        else:
            try:
                res["m"] = analyse(run["log"])
            except LogError as e:
                errors.append(f"{e} [{run['motion']} / {run['ending']}]")
        results.append(res)

    out = []
    out.append("| motion | ending | stop at [s] | tip speed at stop start [m/s] | stop time to "
               "`stopped` [s] | peak spool step [1/cycle] | full-opening reversals [(row, section) "
               "pairs] | peak \\|p_load\\| in stop [MPa] | steady \\|p_load\\| (mean, last 0.5 s) "
               "[MPa] | tip speed at `stopped` [m/s] | time to rest (< 0.01 m/s) [s] |")
    out.append("|" + "---|" * 11)
    inferred = False
    for res in results:
        run, m = res["run"], res["m"]
        label = run["label"]
        if m is None:
            out.append(f"| {label} | {run['ending']} |" + " error |" * 9)
            continue
        inferred |= m["status_inferred"]
        rev = str(m["reversals"])
        if m["reversals"]:
            rev += " (section " + ", ".join(map(str, m["reversal_sections"])) + ")"
        rest = (f"{m['rest_time']:.2f}" if m["rest_time"] is not None
                else f"not at rest at log end ({m['end_speed']:.3f} m/s)")
        stopped = "never" if m["stopped_speed"] is None else f"{m['stopped_speed']:.3f}"
        stop_time = "never" if m["stop_time"] is None else f"{m['stop_time']:.2f}"
        steady = "–" if m["p_steady"] is None else f"{m['p_steady']:.2f}"
        out.append(f"| {label} | {run['ending']} | {m['stop_t']:.2f} | {m['start_speed']:.3f} | "
                   f"{stop_time} | {m['spool_step']:.3f} | {rev} | {m['p_peak']:.2f} | {steady} | "
                   f"{stopped} | {rest} |")

    out.append("")
    out.append("Worst case over the motions, per ending:")
    out.append("")
    endings = [e for e in ENDINGS if any(r["run"]["ending"] == e for r in results)]
    endings += sorted({r["run"]["ending"] for r in results} - set(endings))
    for e in endings:
        ok = [r for r in results if r["run"]["ending"] == e and r["m"] is not None]
        n_err = sum(1 for r in results if r["run"]["ending"] == e and r["m"] is None)
        if not ok:
            out.append(f"- **{e}**: no run measured ({n_err} failed)")
            continue

        def worst(key, fn=None):
            vals = [(r["m"][key], r["run"]["motion"]) for r in ok if r["m"][key] is not None]
            return max(vals, key=fn or (lambda v: v[0])) if vals else None

        step = worst("spool_step")
        rev = worst("reversals")
        n_rev = sum(1 for r in ok if r["m"]["reversals"])
        ratio = [(r["m"]["p_peak"] / r["m"]["p_steady"], r["run"]["motion"], r["m"])
                 for r in ok if r["m"]["p_steady"]]
        pk = max(ratio, key=lambda v: v[0]) if ratio else None
        sp = worst("stopped_speed")
        never = [r["run"]["motion"] for r in ok if r["m"]["stopped_speed"] is None]
        st = worst("stop_time")
        not_rest = [r for r in ok if r["m"]["rest_time"] is None]
        parts = [f"peak spool step {step[0]:.3f} ({step[1]})",
                 f"full-opening reversals in {n_rev}/{len(ok)} runs, most {rev[0]} ({rev[1]})"
                 if rev[0] else f"no full-opening reversal",
                 f"load pressure up to {pk[0]:.2f}× steady ({pk[2]['p_peak']:.2f} vs "
                 f"{pk[2]['p_steady']:.2f} MPa, {pk[1]})" if pk else "load pressure: no steady",
                 f"tip speed at `stopped` up to {sp[0]:.3f} m/s ({sp[1]})" if sp
                 else "never `stopped`",
                 f"stop time up to {st[0]:.2f} s ({st[1]})" if st else ""]
        if never:
            parts.append("never `stopped`: " + ", ".join(never))
        if not_rest:
            w = max(not_rest, key=lambda r: r["m"]["end_speed"])
            parts.append(f"not at rest at log end in {len(not_rest)}/{len(ok)} runs (up to "
                         f"{w['m']['end_speed']:.3f} m/s, {w['run']['motion']})")
        rested = [r for r in ok if r["m"]["rest_time"] is not None]
        if rested:
            w = max(rested, key=lambda r: r["m"]["rest_time"])
            parts.append(f"time to rest up to {w['m']['rest_time']:.2f} s ({w['run']['motion']})")
        if n_err:
            parts.append(f"{n_err} run(s) failed")
        out.append(f"- **{e}**: " + "; ".join(p for p in parts if p) + ".")

    notes = []
    notes.append("Each motion is cut at the time T in its label, with the tip still moving "
                 "(SIGINT: sent T s of wall time after the start; `stop at` is the stop's "
                 "start in the log's machine time). The stop is the last stretch of rows not "
                 "`running`, to the end of the log.")
    if inferred:
        notes.append("The logs have no `status` column (this binary): it is inferred, not "
                     "`running` where `cmd_*` is nan or `active_limit` is `stale_input`, "
                     "`stopped` where besides every spool is exactly 0 (valves neutral).")
    over = [(r["run"]["motion"], r["overruns"]) for r in results
            if r["run"]["ending"] == "SIGINT" and r["overruns"]]
    if over:
        notes.append("Real-time overruns in the SIGINT runs: " +
                     ", ".join(f"{m} {n}" for m, n in over) + ".")
    out.append("")
    out += [f"Note: {n}" for n in notes]
    if errors:
        out.append("")
        out.append("Errors:")
        out += [f"- {e}" for e in errors]
    text = "\n".join(out) + "\n"
    sys.stdout.write(text)
    if args.out:
        with open(args.out, "w") as f:
            f.write(text)
    if errors:
        for e in errors:
            print(f"stop_figures.py: error: {e}", file=sys.stderr)
        sys.exit(1)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    c = sub.add_parser("cut", help="write the -end, -stop and -hold replays of one motion")
    c.add_argument("spec", nargs="+", metavar="SRC T PREFIX",
                   help="source replay, cut time in s, output prefix (repeatable)")
    c.add_argument("--stop-hold", type=float, default=4.0,
                   help="s from the stop row to the last stop row (default 4)")
    c.add_argument("--hold-after", type=float, default=60.0,
                   help="s from the cut to the -hold file's last row (default 60)")
    r = sub.add_parser("report", help="measure the runs of a manifest")
    r.add_argument("manifest")
    r.add_argument("--out", help="also write the Markdown here")
    args = ap.parse_args()
    if args.cmd == "cut":
        cut(args)
    else:
        report(args)


if __name__ == "__main__":
    main()
