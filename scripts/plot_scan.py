#!/usr/bin/python3
"""Top view of one simulated scan (the CSV files of examples/sim_scan): the room's true occupancy,
direct returns, and the phantom points of reflected beams with the true surfaces they came from.

    /usr/bin/python3 scripts/plot_scan.py SCAN_DIR OUT.png [--title TEXT]

Needs Debian's python3-matplotlib. Points on the floor (z < 0.1 m) are left out.
"""
import argparse
import csv
import math
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def read(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("scan_dir")
    ap.add_argument("out_png")
    ap.add_argument("--title", default="One mobile-rig scan in front of the mirror closet (top view)")
    a = ap.parse_args()
    try:
        beams = read(f"{a.scan_dir}/beams.csv")
        truth = read(f"{a.scan_dir}/truth.csv")
        pose = read(f"{a.scan_dir}/pose.csv")[0]
    except (OSError, KeyError, IndexError) as e:
        sys.exit(f"plot_scan: cannot read the scan in {a.scan_dir}: {e}")

    fig, ax = plt.subplots(figsize=(10, 8.5), dpi=100)
    ax.scatter([float(r["x"]) for r in truth], [float(r["y"]) for r in truth], s=9, marker="s", c="#bbbbbb",
               linewidths=0, label="true occupancy (z 0.3-0.4 m)")
    groups = {"direct": ([], [], "#1f5fbf", "direct return"),
              "passed": ([], [], "#2ca02c", "passed through glass"),
              "reflected": ([], [], "#d62728", "phantom: reflected return (where the sensor sees it)")}
    sx, sy = [], []
    for r in beams:
        if r["hit"] != "1" or float(r["z"]) < 0.1 or r["path"] not in groups:
            continue
        xs, ys, _, _ = groups[r["path"]]
        xs.append(float(r["x"]))
        ys.append(float(r["y"]))
        if r["path"] == "reflected":
            sx.append(float(r["sx"]))
            sy.append(float(r["sy"]))
    for xs, ys, colour, label in groups.values():
        if xs:
            ax.scatter(xs, ys, s=2, c=colour, linewidths=0, label=f"{label} ({len(xs)})")
    if sx:
        ax.scatter(sx, sy, s=6, c="#ff9f1c", marker="x", linewidths=0.6,
                   label=f"true surface behind each phantom ({len(sx)})")
    x, y, yaw = float(pose["x"]), float(pose["y"]), float(pose["yaw"])
    ax.plot([x], [y], marker=(3, 0, math.degrees(yaw) - 90), markersize=12, color="black", linestyle="none",
            label="robot (body pose)")
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_title(a.title)
    ax.grid(True, color="#eeeeee")
    leg = ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.1), ncol=2, fontsize=9, framealpha=0.9)
    for h in getattr(leg, "legend_handles", None) or leg.legendHandles:
        if hasattr(h, "set_sizes"):
            h.set_sizes([30])
    fig.tight_layout()
    fig.savefig(a.out_png)


if __name__ == "__main__":
    main()
