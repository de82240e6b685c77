"""Reading craneassist's per-cycle CSV logs (docs/log-format.md) for the plotting scripts, and
what those scripts share in drawing them."""
import csv

TEXT_COLUMNS = ("active_limit", "pump_limit", "status")


def load(path):
    """Returns {column: list of values}: floats, except the text columns. Lines starting with
    '#' (a note on where an archived log comes from, docs/data/) are skipped."""
    with open(path, newline="") as f:
        rows = list(csv.DictReader(line for line in f if not line.startswith("#")))
    if not rows:
        raise SystemExit(f"{path}: no rows")
    # An empty cell is a value the run does not have (load_kg on a machine): NaN.
    cols = {k: [float(r[k]) if r[k] != "" else float("nan") for r in rows]
            for k in rows[0] if k not in TEXT_COLUMNS}
    for k in TEXT_COLUMNS:
        if k in rows[0]:
            cols[k] = [r[k] for r in rows]
    return cols


def pyplot():
    """matplotlib's pyplot on the Agg backend: the scripts write PNG files and need no display."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def label(ax, ylabel, title, xlabel=None):
    """A subplot's y label and title, and its x label when given."""
    ax.set_ylabel(ylabel)
    if xlabel:
        ax.set_xlabel(xlabel)
    ax.set_title(title)


def save(fig, axes, path, dpi, legend_fontsize):
    """A light grid and a legend (upper right) on every subplot, then the figure as a PNG."""
    for a in axes:
        a.grid(True, alpha=0.3)
        a.legend(loc="upper right", fontsize=legend_fontsize)
    fig.tight_layout()
    fig.savefig(path, dpi=dpi)
