#!/usr/bin/python3
"""The flow manipulability polytope of one pose, from `craneassist polytope --out FILE.csv`
(docs/polytope.md): the tip velocities the cylinders and the pump allow, seen from the side,
from above and from behind, and in 3-D, with the stick direction's admissible speed over every
joint motion (LP) and along the controller's resolution. A planar arm's polygon is one plot.

    build/app/craneassist research polytope --pose "lift=20 deg, tilt=-70 deg" --direction 1,0,0.5 \\
        --pump-max-flow "120 L/min" --out poly.csv
    tools/plot_polytope.py poly.csv poly.png
    tools/plot_polytope.py poly.csv --check   # Qhull's volume against craneassist's

`craneassist research polytope --plot FILE.png` runs this script itself. --check computes the hull of the
vertices with Qhull (scipy.spatial.ConvexHull), an implementation independent of craneassist's,
prints both volumes (areas) and exits 1 when they differ by more than 1e-9 of the volume.
Needs python3-matplotlib and python3-scipy (Debian packages).
"""
import argparse
import csv
import sys

import numpy as np
from scipy.spatial import ConvexHull

# The crane frame of craneassist: x forward, y up, z lateral.
VIEWS = [("side", 0, 1), ("top", 0, 2), ("from behind", 2, 1)]


def load(path):
    """The metadata (# key: value lines), the column names and the rows of the CSV."""
    meta, rows, header = {}, [], None
    with open(path, newline="") as f:
        for line in f:
            if line.startswith("#"):
                key, _, value = line[1:].partition(":")
                meta[key.strip()] = value.strip()
            elif header is None:
                header = next(csv.reader([line]))
            elif line.strip():
                rows.append([float(v) for v in next(csv.reader([line]))])
    return meta, header, np.array(rows)


def pyplot():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def qhull_size(points, dimension):
    """Qhull's volume (3-D) or area (2-D) of the points; 0 for a lower-dimensional set."""
    if len(points) <= dimension:
        return 0.0
    try:
        return ConvexHull(points).volume  # in 2-D, Qhull's "volume" is the area
    except Exception:  # flat or degenerate input: no full-dimensional hull
        return 0.0


def polygon(points2):
    """The 2-D hull of the points, closed, counterclockwise."""
    if len(points2) < 3:
        return points2
    h = ConvexHull(points2)
    ring = points2[h.vertices]
    return np.vstack([ring, ring[:1]])


def main():
    p = argparse.ArgumentParser(description=__doc__,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("csv", help="the vertices, from craneassist polytope --out")
    p.add_argument("out", nargs="?", help="the PNG to write")
    p.add_argument("--check", action="store_true",
                   help="compare the volume (area) with Qhull's; exit 1 when they differ")
    a = p.parse_args()
    if not a.out and not a.check:
        p.error("give the PNG to write, --check, or both")
    meta, header, rows = load(a.csv)
    axes = [c[: -len("_m_s")] for c in header if c.endswith("_m_s")]
    dim = len(axes)
    pts = rows[:, :dim] if len(rows) else np.zeros((0, dim))
    size_key = "volume_m3_s3" if dim == 3 else "area_m2_s2"
    size = float(meta.get(size_key, "nan"))
    flat = int(meta.get("dimension", dim)) < dim

    if a.check:
        q = qhull_size(pts, dim)
        unit = "m^3/s^3" if dim == 3 else "m^2/s^2"
        print(f"{'volume' if dim == 3 else 'area'}: craneassist {size:.12g} {unit}, "
              f"Qhull {q:.12g} {unit}")
        if abs(q - size) > 1e-9 * max(abs(q), abs(size), 1e-12):
            print("plot_polytope: the volumes differ", file=sys.stderr)
            return 1
        print("plot_polytope: they agree to 1e-9")
    if not a.out:
        return 0

    u = np.array([float(v) for v in meta["direction"].split(",")]) if "direction" in meta else None
    best = float(meta.get("best_speed_m_s", "nan"))
    resolved = float(meta.get("resolved_speed_m_s", "nan"))
    resolution = meta.get("resolution", "the controller's resolution")

    plt = pyplot()
    views = VIEWS if dim == 3 else [("in the arm's plane", 0, 1)]
    fig = plt.figure(figsize=(12, 10.5) if dim == 3 else (7, 7), constrained_layout=True)
    # The panels, and a row below them for the legend (inside a panel it would hide data).
    grid = (fig.add_gridspec(3, 2, height_ratios=[1, 1, 0.08]) if dim == 3
            else fig.add_gridspec(2, 1, height_ratios=[1, 0.1]))
    cells = [grid[0, 0], grid[0, 1], grid[1, 0], grid[1, 1]] if dim == 3 else [grid[0, 0]]
    title = meta.get("title", "flow manipulability polytope")
    size_text = (f"volume {size:.3g} m$^3$/s$^3$" if dim == 3 and not flat
                 else f"area {float(meta.get('area_m2_s2', 0)):.3g} m$^2$/s$^2$")
    fig.suptitle(f"{title}\n{meta.get('pose', '')}; {size_text}", fontsize=11)
    for k, (name, i, j) in enumerate(views):
        ax = fig.add_subplot(cells[k])
        ring = polygon(pts[:, [i, j]]) if len(pts) else pts
        ax.fill(ring[:, 0], ring[:, 1], color="tab:orange", alpha=0.35, lw=0)
        ax.plot(ring[:, 0], ring[:, 1], color="tab:orange", lw=1.5)
        ax.plot(pts[:, i], pts[:, j], ".", color="tab:brown", ms=4, label="vertices")
        if u is not None:
            ax.annotate("", xy=(best * u[i], best * u[j]), xytext=(0, 0),
                        arrowprops=dict(arrowstyle="->", color="tab:blue", lw=2))
            ax.plot([best * u[i]], [best * u[j]], "o", color="tab:blue",
                    label=f"best joint motion (LP): {best:.2f} m/s")
            ax.plot([resolved * u[i]], [resolved * u[j]], "s", color="tab:green", mfc="none",
                    ms=9, mew=2, label=f"along the {resolution} resolution: {resolved:.2f} m/s")
        ax.plot([0], [0], "k+", ms=10)
        ax.set_xlabel(f"{axes[i]} velocity, m/s")
        ax.set_ylabel(f"{axes[j]} velocity, m/s")
        ax.set_title(name)
        ax.set_aspect("equal", adjustable="datalim")
        ax.grid(alpha=0.3)
        if k == 0:
            handles, labels = ax.get_legend_handles_labels()
    if dim == 3:
        ax = fig.add_subplot(cells[3], projection="3d")
        if not flat and len(pts) >= 4:
            hull = ConvexHull(pts)
            # Matplotlib's 3-D axes have z up: show the crane's up (y) as up.
            ax.plot_trisurf(pts[:, 0], pts[:, 2], pts[:, 1], triangles=hull.simplices,
                            color="tab:orange", alpha=0.35, edgecolor="tab:brown", lw=0.3)
        ax.scatter(pts[:, 0], pts[:, 2], pts[:, 1], color="tab:brown", s=6)
        if u is not None:
            ax.plot([0, best * u[0]], [0, best * u[2]], [0, best * u[1]], color="tab:blue", lw=2)
        ax.set_xlabel("x (forward), m/s")
        ax.set_ylabel("z (lateral), m/s")
        ax.set_zlabel("y (up), m/s")
        ax.set_title("3-D")
        ax.tick_params(labelsize=7)
        ax.set_box_aspect(np.ptp(pts[:, [0, 2, 1]], axis=0) + 1e-9)
    legend = fig.add_subplot(grid[-1, :])
    legend.axis("off")
    legend.legend(handles, labels, loc="center", ncol=3, fontsize=9, frameon=False)
    fig.savefig(a.out, dpi=110)
    print(f"plot_polytope: wrote {a.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
