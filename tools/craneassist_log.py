"""Reading craneassist's per-cycle CSV logs (docs/log-format.md) for the plotting scripts."""
import csv

TEXT_COLUMNS = ("active_limit", "pump_limit")


def load(path):
    """Returns {column: list of values}: floats, except the text columns. Lines starting with
    '#' (a note on where an archived log comes from, docs/data/) are skipped."""
    with open(path, newline="") as f:
        rows = list(csv.DictReader(line for line in f if not line.startswith("#")))
    if not rows:
        raise SystemExit(f"{path}: no rows")
    cols = {k: [float(r[k]) for r in rows] for k in rows[0] if k not in TEXT_COLUMNS}
    for k in TEXT_COLUMNS:
        if k in rows[0]:
            cols[k] = [r[k] for r in rows]
    return cols
