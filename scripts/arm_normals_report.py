"""The table of issue 34's runs (scripts/arm_normals_sweep.sh) from its CSV: per update, with
and without views that seek normals, the grid's coverage of the part's visible surface and its
wrongly occupied voxels, the explained model's coverage, size and wrongly occupied voxels (mean ±
sd), the runs whose explained model reaches 80 % within the budget, and the effect of seeking
normals on the explained model's coverage (difference of means, 95 % percentile bootstrap
interval, seeded). Needs numpy.

With --before CSV (rows object,material,update,seed,coverage_percent,wrongly_occupied of the same
object from an earlier build), also the grid's coverage against that one: difference of means with
its bootstrap interval, with and without seeking normals.

Usage: python3 scripts/arm_normals_report.py arm_normals.csv [--before before.csv] [--resamples N] [--seed S]"""
import argparse
import csv
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from bootstrap import bootstrap_diff, mean_sd  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("csv")
    ap.add_argument("--resamples", type=int, default=10000)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--before", help="CSV of the same object's runs from an earlier build")
    a = ap.parse_args()
    rows = list(csv.DictReader(open(a.csv, newline="")))
    if not rows:
        sys.exit("arm_normals_report: no rows in " + a.csv)
    rng = np.random.default_rng(a.seed)
    col = lambda rs, k: [float(r[k]) for r in rs]  # noqa: E731
    updates = list(dict.fromkeys(r["update"] for r in rows))
    print(f"{rows[0]['object']}, {rows[0]['material']}: {len(rows)} runs")
    print("| update | normals | runs | grid coverage % | grid wrongly occupied | explained model coverage % | "
          "model voxels | model wrongly occupied | model >= 80 % | views with reason normals |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for u in updates:
        for n in ("off", "on"):
            rs = [r for r in rows if r["update"] == u and r["normals"] == n]
            if not rs:
                continue
            reach = sum(1 for r in rs if float(r["model_coverage_percent"]) >= 80.0)
            print(f"| {u} | {n} | {len(rs)} | {mean_sd(col(rs, 'coverage_percent'), 1)} | "
                  f"{mean_sd(col(rs, 'wrongly_occupied'), 1)} | {mean_sd(col(rs, 'model_coverage_percent'), 1)} | "
                  f"{mean_sd(col(rs, 'model_voxels'), 0)} | {mean_sd(col(rs, 'model_wrongly_occupied'), 0)} | "
                  f"{reach} of {len(rs)} | {mean_sd(col(rs, 'normals_views'), 1)} |")
    print()
    print("Seeking normals, effect on the explained model's coverage (percentage points, on - off, 95 % bootstrap CI):")
    for u in updates:
        on = col([r for r in rows if r["update"] == u and r["normals"] == "on"], "model_coverage_percent")
        off = col([r for r in rows if r["update"] == u and r["normals"] == "off"], "model_coverage_percent")
        b = bootstrap_diff(on, off, a.resamples, rng)
        print(f"- {u}: " + ("–" if b is None else f"{b[0]:+.1f} [{b[1]:+.1f}, {b[2]:+.1f}]"))
    if a.before:
        obj = rows[0]["object"]
        before = [r for r in csv.DictReader(open(a.before, newline="")) if r["object"] == obj]
        print()
        print(f"Grid coverage % against {os.path.basename(a.before)} (difference of means, 95 % bootstrap CI):")
        print("| update | before | normals off | off - before | normals on | on - before |")
        print("|---|---|---|---|---|---|")
        for u in updates:
            old = col([r for r in before if r["update"] == u], "coverage_percent")
            line = f"| {u} | {mean_sd(old, 1)} |"
            for n in ("off", "on"):
                v = col([r for r in rows if r["update"] == u and r["normals"] == n], "coverage_percent")
                b = bootstrap_diff(v, old, a.resamples, rng)
                line += f" {mean_sd(v, 1)} | " + ("–" if b is None else f"{b[0]:+.1f} [{b[1]:+.1f}, {b[2]:+.1f}]") + " |"
            print(line)


if __name__ == "__main__":
    main()
