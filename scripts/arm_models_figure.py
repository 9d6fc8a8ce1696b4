"""The figure of issue 34: the polished part's model after 12 views, seen from above. Panels: the
Bayes grid's occupied voxels, the interval-mean grid's, and the explained model (the
explained-occupied voxels of the interval-mean run), each from arm_modelling's PLY output of the
same seed with views that seek normals, with each model's coverage and wrongly occupied voxels in
its title (arm_modelling's summary), over the part's true voxel columns (the simulator's ground
truth, from the Python module). Needs matplotlib (Debian: python3-matplotlib) and the built Python
module (PYTHONPATH=build/python).

Usage: PYTHONPATH=build/python python3 scripts/arm_models_figure.py [--build build] [--seed 1]
       [--out docs/figures/arm_models_polished.png]"""
import argparse
import os
import re
import struct
import subprocess
import sys
import tempfile

import matplotlib
import numpy as np

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.patches import Patch  # noqa: E402


def read_ply_points(path):
    """The vertices (x, y, z) of an Intervox binary PLY point export (float x, y, z first)."""
    data = open(path, "rb").read()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:end].decode("ascii").splitlines()
    if "format binary_little_endian 1.0" not in header:
        sys.exit(f"arm_models_figure: {path} is not a binary little-endian PLY")
    count = next(int(line.split()[2]) for line in header if line.startswith("element vertex"))
    props = [line.split()[1:] for line in header if line.startswith("property")]
    sizes = {"float": 4, "uchar": 1, "int": 4}
    stride = sum(sizes[t] for t, _ in props)
    return [struct.unpack_from("<fff", data, end + i * stride) for i in range(count)]


def run(build, update, seed, out):
    """Runs arm_modelling on the polished part and returns its summary's numbers."""
    exe = os.path.join(build, "examples", "arm_modelling", "arm_modelling")
    log = subprocess.run([exe, "--update", update, "--utility", "max-entropy", "--material", "polished-metal",
                          "--seek-normals", "--max-views", "12", "--threads", "1", "--seed", str(seed), "--out", out],
                         check=True, capture_output=True, text=True).stdout
    grid = re.search(r"surface known occupied\s+([\d.]+) %", log)
    wrong = re.search(r"voxels wrongly occupied\s+(\d+)", log)
    model = re.search(r"explained model\s+(\d+) voxels, ([\d.]+) % of the visible surface, (\d+) wrongly occupied", log)
    if not (grid and wrong and model):
        sys.exit("arm_models_figure: cannot read arm_modelling's summary:\n" + log)
    return {"grid": float(grid.group(1)), "grid_wrong": int(wrong.group(1)), "model_voxels": int(model.group(1)),
            "model": float(model.group(2)), "model_wrong": int(model.group(3))}


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--build", default="build")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--out", default="docs/figures/arm_models_polished.png")
    a = ap.parse_args()
    import intervox as iv  # the built module: PYTHONPATH=<build>/python

    cell = iv.make_workcell()
    keys = np.asarray(cell.scene.ground_truth(0.01, cell.object_region("part", 0.01)))
    truth = sorted({((k[0] + 0.5) * 0.01, (k[1] + 0.5) * 0.01) for k in keys if (k[2] + 0.5) * 0.01 >= 0.75})
    with tempfile.TemporaryDirectory() as tmp:
        panels = []
        for update in ("bayes", "interval-mean"):
            out = os.path.join(tmp, update)
            r = run(a.build, update, a.seed, out)
            panels.append((f"{update}: the grid's occupied voxels\n{r['grid']:.1f} % of the visible surface, "
                           f"{r['grid_wrong']} wrongly occupied", read_ply_points(os.path.join(out, "model.ply")), "#202020"))
            if update == "interval-mean":
                panels.append((f"{update}: the explained model\n{r['model']:.1f} % of the visible surface, "
                               f"{r['model_wrong']} wrongly occupied", read_ply_points(os.path.join(out, "model_explained.ply")),
                               "#1f5fbf"))
    fig, axes = plt.subplots(1, 3, figsize=(13.5, 5.8))
    for ax, (title, points, colour) in zip(axes, panels):
        # Seen from above: the part's true columns underneath, the voxel layer on the table top
        # (z < 0.75 m) lighter, the model's voxels above it on top.
        ax.scatter([p[0] for p in truth], [p[1] for p in truth], s=90, marker="s", c="#f6c48a", linewidths=0)
        top = [(x, y) for x, y, z in points if z >= 0.75]
        foot = [(x, y) for x, y, z in points if z < 0.75]
        if foot:
            ax.scatter([p[0] for p in foot], [p[1] for p in foot], s=22, marker="s", c="#9a9a9a", linewidths=0)
        if top:
            ax.scatter([p[0] for p in top], [p[1] for p in top], s=22, marker="s", c=colour, linewidths=0)
        ax.set_title(title, fontsize=10)
        ax.set_xlim(0.63, 0.87)
        ax.set_ylim(0.63, 0.87)
        ax.set_aspect("equal")
        ax.set_xlabel("x [m]")
        ax.set_ylabel("y [m]")
    fig.legend(handles=[Patch(color="#f6c48a", label="the part (ground truth, above the table-top layer)"),
                        Patch(color="#202020", label="grid: occupied voxel above the table-top layer"),
                        Patch(color="#1f5fbf", label="explained model: explained-occupied voxel above that layer"),
                        Patch(color="#b0b0b0", label="voxel in the table-top layer (0.74-0.75 m)")],
               loc="lower center", ncol=2, fontsize=9, frameon=False)
    fig.suptitle(f"Polished ring part after 12 views, seeking normals, seed {a.seed} (seen from above; "
                 "1 cm voxels; 336 visible surface voxels)", fontsize=11)
    fig.tight_layout(rect=(0, 0.12, 1, 0.95))
    os.makedirs(os.path.dirname(os.path.abspath(a.out)), exist_ok=True)
    fig.savefig(a.out, dpi=110)
    print(f"arm_models_figure: wrote {a.out}")


if __name__ == "__main__":
    main()
