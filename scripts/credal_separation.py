#!/usr/bin/env python3
"""Separation of the conflict signature per update policy, from an experiments results.csv.

For every mobile configuration (closet surface, update, policy preset, planner) with detector
scores: voxels flagged by the conflict detector inside the conflict band (behind and in front of
the closet) and outside it, the share inside, the signature voxels likewise, and the detector's
precision (left out of runs that flag nothing) and recall against the simulator's labels, as
mean +- sd over the seeds. Then the
differences of means with a 95 % bootstrap confidence interval (percentile method, seeded,
groups resampled independently): each credal update against the thesis' interval update on the
same surface and planner, and the mirror closet against the diffuse one for each update.

Usage: credal_separation.py RESULTS_CSV [--reference interval-mean/thesis] [--resamples N] [--seed S]
Writes Markdown to standard output. Needs numpy.
"""
import argparse
import csv
import math
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from bootstrap import bootstrap_diff, mean_sd  # noqa: E402


def load(path):
    """Mobile rows with detector scores, as dicts with the derived shares."""
    rows = []
    with open(path, newline="") as f:
        for r in csv.DictReader(f):
            if r["platform"] != "mobile" or int(r.get("flagged_voxels", "-1")) < 0:
                continue
            d = {k: r[k] for k in ("surface", "update", "policies", "planner", "seed")}
            # Only the interval updates have presets; the credal cells run their defaults.
            d["label"] = r["update"] + ("/" + r["policies"] if r["update"].startswith("interval") else "")
            for k in ("flagged_voxels", "flagged_band", "signature_voxels", "signature_band", "conflict_truth",
                      "truth_band"):
                d[k] = int(r[k])
            # The detector's precision is 1 by definition when it flags nothing; left out here.
            d["precision"] = float(r["conflict_precision"]) if d["flagged_voxels"] else math.nan
            d["recall"] = float(r["conflict_recall"])
            d["flagged_outside"] = d["flagged_voxels"] - d["flagged_band"]
            d["signature_outside"] = d["signature_voxels"] - d["signature_band"]
            d["flagged_share"] = d["flagged_band"] / d["flagged_voxels"] if d["flagged_voxels"] else math.nan
            d["signature_share"] = d["signature_band"] / d["signature_voxels"] if d["signature_voxels"] else math.nan
            d["truth_share"] = d["truth_band"] / d["conflict_truth"] if d["conflict_truth"] else math.nan
            rows.append(d)
    return rows


def values(rows, metric):
    v = np.array([r[metric] for r in rows], dtype=float)
    return v[~np.isnan(v)]


METRICS = [  # (column, header, digits)
    ("flagged_band", "flagged in band", 0),
    ("flagged_outside", "flagged outside", 0),
    ("flagged_share", "share of flagged in band", 2),
    ("signature_band", "signature in band", 0),
    ("signature_outside", "signature outside", 0),
    ("precision", "precision", 3),
    ("recall", "recall", 3),
]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("results")
    ap.add_argument("--reference", default="interval-mean/thesis", help="update (interval: update/preset) the credal rows are compared with")
    ap.add_argument("--resamples", type=int, default=10000)
    ap.add_argument("--seed", type=int, default=20)
    a = ap.parse_args()
    rows = load(a.results)
    if not rows:
        sys.exit(f"{a.results}: no mobile rows with detector scores")
    rng = np.random.default_rng(a.seed)
    groups = {}
    for r in rows:
        groups.setdefault((r["planner"], r["surface"], r["label"]), []).append(r)
    print("| planner | closet | update / preset | runs | " + " | ".join(h for _, h, _ in METRICS) +
          " | truth in band / all |")
    print("|---" * (5 + len(METRICS)) + "|")
    for key in sorted(groups, key=lambda k: (k[0] != "plain", k[0], k[1], k[2] != a.reference, k[2])):
        g = groups[key]
        cells = [mean_sd(values(g, m), d) for m, _, d in METRICS]
        truth = f"{np.mean(values(g, 'truth_band')):.0f} / {np.mean(values(g, 'conflict_truth')):.0f}"
        print(f"| {key[0]} | {key[1]} | {key[2]} | {len(g)} | " + " | ".join(cells) + f" | {truth} |")
    print()
    print(f"Differences of means, 95 % bootstrap interval ({a.resamples} resamples, seed {a.seed}):")
    print()
    print("| planner | comparison | metric | difference | 95 % CI |")
    print("|---|---|---|---|---|")
    planners = sorted({k[0] for k in groups}, key=lambda p: p != "plain")
    for planner in planners:
        for surface in sorted({k[1] for k in groups if k[0] == planner}, key=lambda s: s != "mirror"):
            ref = groups.get((planner, surface, a.reference))
            if not ref:
                continue
            for upd in sorted(k[2] for k in groups if k[0] == planner and k[1] == surface and k[2] != a.reference):
                for m, h, d in METRICS:
                    if m in ("flagged_outside", "signature_band", "signature_outside"):
                        continue
                    r = bootstrap_diff(values(groups[(planner, surface, upd)], m), values(ref, m), a.resamples, rng)
                    if r:
                        print(f"| {planner} | {surface}: {upd} − {a.reference} | {h} | {r[0]:+.{d}f} | "
                              f"[{r[1]:+.{d}f}, {r[2]:+.{d}f}] |")
        for upd in sorted({k[2] for k in groups if k[0] == planner}):
            mir, dif = groups.get((planner, "mirror", upd)), groups.get((planner, "diffuse", upd))
            if not mir or not dif:
                continue
            for m, h, d in METRICS[:3]:
                r = bootstrap_diff(values(mir, m), values(dif, m), a.resamples, rng)
                if r:
                    print(f"| {planner} | {upd}: mirror − diffuse | {h} | {r[0]:+.{d}f} | [{r[1]:+.{d}f}, {r[2]:+.{d}f}] |")


if __name__ == "__main__":
    main()
