#!/usr/bin/python3
"""Plot what the operator feels, before and after, from craneassist logs of replays whose
commands all lie on one line through zero (a push, a reversal): the measured tip speed along
that line with the commanded speed, and the tip speed across it (averaged over 50 ms, as the
replay summary's "operator feel" line and the scenario suite measure it).

    craneassist replay examples/replays/suite/push_x_plus.csv --log push.csv
    craneassist replay examples/replays/suite/reversal_slow.csv --log reversal.csv
    tools/plot_feel.py docs/img/operator_feel.png \\
        --run "push straight out" docs/data/feel-before/push_x_plus.csv push.csv \\
        --run "slow reversal" docs/data/feel-before/reversal_slow.csv reversal.csv

Each --run gives a title, the log before and the log after. Needs python3-matplotlib (Debian
package).
"""
import argparse
import math

from craneassist_log import load, pyplot

plt = pyplot()

WINDOW = 5  # cycles: 50 ms at 100 Hz


def line_of(c):
    """The unit vector of the commands' line (the first non-zero command)."""
    for i in range(len(c["t"])):
        v = [c["cmd_vx"][i], c["cmd_vy"][i], c["cmd_vz"][i]]
        n = math.sqrt(sum(x * x for x in v))
        if n > 0 and math.isfinite(n):
            return [x / n for x in v]
    raise SystemExit("no command in the log")


def along_and_across(c, line):
    """Commanded and measured speed along the line, and the measured speed across it over 50 ms."""
    cmd, along, across = [], [], []
    n = len(c["t"])
    for i in range(n):
        v_cmd = [c["cmd_vx"][i], c["cmd_vy"][i], c["cmd_vz"][i]]
        cmd.append(sum(a * b for a, b in zip(v_cmd, line)) if all(map(math.isfinite, v_cmd)) else 0)
        tip = [c["tip_vx"][i], c["tip_vy"][i], c["tip_vz"][i]]
        along.append(sum(a * b for a, b in zip(tip, line)))
        lo = max(0, i - WINDOW + 1)
        mean = [sum(c[k][lo : i + 1]) / (i + 1 - lo) for k in ("tip_vx", "tip_vy", "tip_vz")]
        par = sum(a * b for a, b in zip(mean, line))
        across.append(math.sqrt(max(0.0, sum(x * x for x in mean) - par * par)))
    return cmd, along, across


def main():
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("out", help="PNG to write")
    parser.add_argument("--run", nargs=3, action="append", required=True,
                        metavar=("TITLE", "BEFORE", "AFTER"))
    parser.add_argument("--labels", nargs=2, default=["before", "now"])
    parser.add_argument("--lateral-target", type=float, default=0.03,
                        help="the suite's target for the speed across the line, m/s")
    args = parser.parse_args()

    fig, axes = plt.subplots(len(args.run), 2, figsize=(11, 3.2 * len(args.run)), squeeze=False)
    for row, (title, before, after) in enumerate(args.run):
        logs = [load(before), load(after)]
        line = line_of(logs[1])
        ax_along, ax_across = axes[row]
        for k, (c, label, style) in enumerate(zip(logs, args.labels, ("C3", "C0"))):
            cmd, along, across = along_and_across(c, line)
            if k == 1:
                ax_along.plot(c["t"], cmd, color="0.6", ls="--", lw=1, label="stick")
            ax_along.plot(c["t"], along, color=style, lw=1.2, label=label)
            ax_across.plot(c["t"], across, color=style, lw=1.2,
                           label=f"{label}: peak {max(across):.3f} m/s")
        ax_across.axhline(args.lateral_target, color="k", ls=":", lw=1,
                          label=f"target {args.lateral_target} m/s")
        ax_along.set_title(f"{title}: tip speed along the stick's line")
        ax_along.set_ylabel("m/s")
        ax_across.set_title(f"{title}: tip speed across the line (50 ms)")
        ax_across.set_ylabel("m/s")
        ax_along.legend(loc="best", fontsize=8)
        ax_across.legend(loc="best", fontsize=8)
        for ax in (ax_along, ax_across):
            ax.grid(alpha=0.3)
    for ax in axes[-1]:
        ax.set_xlabel("t (s)")
    fig.tight_layout()
    fig.savefig(args.out, dpi=110)


if __name__ == "__main__":
    main()
