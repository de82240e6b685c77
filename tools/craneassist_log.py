"""Reading craneassist's per-cycle CSV logs (docs/log-format.md) for the plotting scripts."""
import csv

TEXT_COLUMNS = ("active_limit", "pump_limit")


def load(path):
    """Returns {column: list of values}: floats, except the text columns."""
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    if not rows:
        raise SystemExit(f"{path}: no rows")
    cols = {k: [float(r[k]) for r in rows] for k in rows[0] if k not in TEXT_COLUMNS}
    for k in TEXT_COLUMNS:
        cols[k] = [r[k] for r in rows]
    return cols
