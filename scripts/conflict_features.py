#!/usr/bin/env python3
"""Scores label-free conflict detection rules on the per-voxel rows of conflict_features
(examples/experiments/conflict_features.cpp) against the simulator's ground truth.

    python3 scripts/conflict_features.py specular_1.csv specular_2.csv diffuse_1.csv ...
    python3 scripts/conflict_features.py --figure specular_1.png specular_1.csv
    python3 scripts/conflict_features.py --reduce DIR [--scene] specular_1.csv ...

Files are grouped by the surface named before the first '_' of their file name. For every rule
and group it prints, as a Markdown table, flagged voxels, precision and recall (mean +- sd over the
group's files) and the share of the diffuse room's surface-edge voxels flagged (edge voxels:
observed, occupied in the scene or next to one, without phantom evidence, as score_conflicts).
Two ground truths are scored: `implemented` (eval/conflict_scoring.hpp: hits and misses each >= 20 % of
the voxel's observations, phantom evidence >= 20 %) and `issue` (the issue's wording: phantom and
true evidence each >= 20 %). `--figure` draws one file's rows from above instead (matplotlib).

`--reduce DIR` writes each file's rows that the table reads, gzipped, to DIR/NAME.gz (same
columns, rows verbatim and in order): the voxels any rule flags or either ground truth holds and,
in a diffuse file, every voxel in the 26-neighbourhood of a scene-occupied one (the edge voxels
and what makes them edges); with `--scene`, also every scene-occupied voxel (the figure's
background). The table of the reduced files equals the table of the full ones. Files ending in
.gz are read as gzip. Needs numpy.
"""
import gzip
import os
import sys

try:
    import numpy as np
except ImportError:  # pragma: no cover - reported, not a failure of the data
    print("conflict_features.py: needs numpy", file=sys.stderr)
    sys.exit(77)

COLUMNS = ["x", "y", "z", "scene_occupied", "truth", "phantom", "true_evidence", "observations", "map", "hits",
           "misses", "hit_on_free", "miss_on_occupied", "pass_occupied", "hit_behind_occupied", "fringe"]
SHARE = 0.2


def open_text(path, mode="rt"):
    """A CSV file, gzipped if its name ends in .gz (written with mtime 0: the same rows give the
    same bytes)."""
    if path.endswith(".gz"):
        return gzip.open(path, mode) if "r" in mode else gzip.GzipFile(path, "wb", 9, mtime=0)
    return open(path, mode)


def load(path):
    with open_text(path) as f:
        header = f.readline().strip().split(",")
    if header != COLUMNS:
        raise SystemExit(f"conflict_features.py: {path}: unexpected header {header}")
    data = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    if data.shape[0] == 0:
        raise SystemExit(f"conflict_features.py: {path}: no rows")
    return {name: data[:, i] for i, name in enumerate(COLUMNS)}


def neighbours_occupied(d):
    """Voxels with a scene-occupied voxel in their 26-neighbourhood (or occupied themselves)."""
    res = 0.05
    keys = np.floor(np.stack([d["x"], d["y"], d["z"]], axis=1) / res).astype(np.int64) + (1 << 20)

    def code(k):
        return (k[:, 0] << 42) | (k[:, 1] << 21) | k[:, 2]

    occ = code(keys[d["scene_occupied"] == 1])
    out = np.zeros(len(keys), dtype=bool)
    for off in [(a, b, c) for a in (-1, 0, 1) for b in (-1, 0, 1) for c in (-1, 0, 1)]:
        out |= np.isin(code(keys + np.array(off)), occ)
    return out


FRINGE_RULE = "the same, surface-fringe rule (no map-occupied neighbour)"
PASS_RULE = "the same, and >= 20 % of observations"


def rules(d):
    h, m = d["hits"], d["misses"]
    n = h + m
    record = d["hit_on_free"] + d["miss_on_occupied"]
    contra = (n >= 4) & (h >= SHARE * n) & (m >= SHARE * n)
    return [
        ("hits and misses each >= 20 %, >= 4 observations", contra),
        ("the same, surface-fringe rule (no map-occupied neighbour)", contra & (d["fringe"] == 0)),
        ("contradictions of the map's state >= 2", record >= 2),
        ("contradictions of the map's state >= 8", record >= 8),
        ("contradictions >= 2 and >= 20 % of observations", (record >= 2) & (record >= SHARE * n)),
        ("misses of map-occupied voxels ending > 0.25 m beyond >= 2", d["pass_occupied"] >= 2),
        ("the same, and >= 20 % of observations", (d["pass_occupied"] >= 2) & (d["pass_occupied"] >= SHARE * n)),
        ("returns behind a map-occupied voxel >= 2", d["hit_behind_occupied"] >= 2),
    ]


def truths(d):
    t = d["observations"]
    return {
        "implemented": d["truth"] == 1,
        "issue": (d["phantom"] > 0) & (d["true_evidence"] > 0) & (d["phantom"] >= SHARE * t) & (d["true_evidence"] >= SHARE * t),
    }


def fmt(values, digits=3):
    a = np.asarray(values, dtype=float)
    if len(a) == 1:
        return f"{a[0]:.{digits}f}"
    return f"{a.mean():.{digits}f} ± {a.std(ddof=1):.{digits}f}"


def surface_of(path):
    """The closet of a rows file: its name before the first '_'."""
    return os.path.basename(path).split("_")[0]


def reduce_rows(path, out, scene=False):
    """Writes the rows of \\p path that score() reads (and, with \\p scene, the scene-occupied ones
    figure() draws) to \\p out, gzipped if its name ends in .gz. Returns (rows kept, rows)."""
    d = load(path)
    keep = np.zeros(len(d["x"]), dtype=bool)
    for _, flag in rules(d):
        keep |= flag
    for gt in truths(d).values():
        keep |= gt
    if surface_of(path) == "diffuse":  # edge voxels and the occupied voxels that make them edges
        keep |= neighbours_occupied(d)
    if scene:
        keep |= d["scene_occupied"] == 1
    with open_text(path) as f:
        lines = f.readlines()
    if len(lines) != len(keep) + 1:
        raise SystemExit(f"conflict_features.py: {path}: {len(lines) - 1} lines but {len(keep)} rows")
    text = lines[0] + "".join(lines[1 + i] for i in np.flatnonzero(keep))
    with open_text(out, "w") as f:
        f.write(text.encode() if out.endswith(".gz") else text)
    return int(keep.sum()), len(keep)


def score(paths):
    """{(closet, rule, ground truth): {"flagged", "truth", "precision", "recall", "edge": per-file lists}}."""
    groups = {}
    for p in paths:
        groups.setdefault(surface_of(p), []).append(p)
    rows = {}
    for surface, files in sorted(groups.items()):
        for path in files:
            d = load(path)
            edge = neighbours_occupied(d) & (d["phantom"] == 0) if surface == "diffuse" else None
            for name, flag in rules(d):
                for gname, gt in truths(d).items():
                    tp = int((flag & gt).sum())
                    k = int(flag.sum())
                    r = rows.setdefault((surface, name, gname), {"flagged": [], "precision": [], "recall": [], "truth": [], "edge": []})
                    r["flagged"].append(k)
                    r["truth"].append(int(gt.sum()))
                    if k:  # precision is left out of files where the rule flags nothing
                        r["precision"].append(tp / k)
                    r["recall"].append(tp / gt.sum() if gt.sum() else 1.0)
                    if edge is not None:
                        r["edge"].append((flag & edge).sum() / max(edge.sum(), 1))
    return rows


def table(rows):
    """The Markdown table of score()'s rows."""
    lines = ["| closet | rule | ground truth | files | truth voxels | flagged | precision | recall | diffuse edge voxels flagged |",
             "|---|---|---|---|---|---|---|---|---|"]
    for (surface, name, gname), r in rows.items():
        edge = fmt(100 * np.asarray(r["edge"]), 1) + " %" if r["edge"] else "–"
        prec = fmt(r["precision"]) if r["precision"] else "– (none flagged)"
        lines.append(f"| {surface} | {name} | {gname} | {len(r['recall'])} | {fmt(r['truth'], 0)} | {fmt(r['flagged'], 0)} | "
                     f"{prec} | {fmt(r['recall'])} | {edge} |")
    return "\n".join(lines) + "\n"


def figure(path, out):
    """Top view of one run's rows (the lab room, 0.05 m columns): where the ground truth's conflict
    voxels lie and what two rules flag, over the scene's obstacles. Needs matplotlib."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    d = load(path)
    flags = dict(rules(d))
    gts = truths(d)
    panels = [
        ("ground truth", [("implemented (eval/conflict_scoring.hpp)", gts["implemented"], "tab:orange"),
                          ("issue's wording (phantom and true evidence)", gts["issue"], "tab:red")]),
        ("flagged", [("hits and misses each ≥ 20 %, surface-fringe rule", flags[FRINGE_RULE], "tab:blue"),
                     ("pass-through misses ≥ 2 and ≥ 20 %", flags[PASS_RULE], "tab:purple")]),
    ]
    occupied = d["scene_occupied"] == 1
    fig, axes = plt.subplots(1, 2, figsize=(13, 5.6), sharey=True)
    for ax, (title, layers) in zip(axes, panels):
        ax.scatter(d["x"][occupied], d["y"][occupied], s=1, c="0.8", marker="s", linewidths=0, label="occupied in the scene")
        for label, mask, colour in layers:
            ax.scatter(d["x"][mask], d["y"][mask], s=4, c=colour, marker="s", linewidths=0,
                       label=f"{label}: {int(mask.sum())} voxels")
        ax.axvspan(-0.1, 0.0, color="0.5", alpha=0.3, lw=0)
        ax.add_patch(matplotlib.patches.Rectangle((0.001, 3.4), 0.6, 1.2, fill=False, ec="black", lw=1.2, ls="--"))
        ax.text(0.65, 4.65, "closet", fontsize=9)
        ax.set_title(title)
        ax.set_xlabel("x (m)")
        ax.set_xlim(-4.5, 8.3)
        ax.set_ylim(-0.3, 6.3)
        ax.set_aspect("equal")
        ax.legend(loc="lower right", fontsize=8, markerscale=4, framealpha=0.9)
    axes[0].set_ylabel("y (m)")
    name = os.path.basename(path).removesuffix(".gz")
    fig.suptitle(f"{name}: voxels at any height seen from above; the west wall shaded (x < 0: behind it)")
    fig.tight_layout()
    fig.savefig(out, dpi=110)


def main(args):
    if "--reduce" in args:
        i = args.index("--reduce")
        if i + 1 >= len(args):
            raise SystemExit("usage: conflict_features.py --reduce DIR [--scene] FILE.csv...")
        folder = args[i + 1]
        rest = args[:i] + args[i + 2:]
        scene = "--scene" in rest
        files = [a for a in rest if a != "--scene"]
        if not files:
            raise SystemExit("usage: conflict_features.py --reduce DIR [--scene] FILE.csv...")
        os.makedirs(folder, exist_ok=True)
        for path in files:
            out = os.path.join(folder, os.path.basename(path).removesuffix(".gz") + ".gz")
            kept, total = reduce_rows(path, out, scene)
            print(f"{out}: {kept} of {total} rows")
        return
    if "--figure" in args:
        i = args.index("--figure")
        if len(args) != 3 or i + 1 >= len(args):
            raise SystemExit("usage: conflict_features.py --figure OUT.png FILE.csv")
        rest = args[:i] + args[i + 2:]
        figure(rest[0], args[i + 1])
        return
    if not args:
        raise SystemExit("usage: conflict_features.py FILE.csv... | --figure OUT.png FILE.csv | --reduce DIR [--scene] FILE.csv...")
    sys.stdout.write(table(score(args)))


if __name__ == "__main__":
    main(sys.argv[1:])
