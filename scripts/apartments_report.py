#!/usr/bin/python3
"""The report of the apartments benchmark (examples/apartments, docs/experiments.md "Random
apartments") from its results.csv (and timings.csv beside it).

Usage: apartments_report.py RESULTS_CSV [--resamples N] [--seed S] [--charts DIR] > report.md

Per rig and update, every planner in the apartments (world "lying") and in their honest twins
(world "honest"): the runs with a collision against the true world, the completed runs (ended by
themselves: explored, or no reachable frontier left), the reachable floor known, the views, and
against the oracle (the plain planner told every lying surface), paired by world: the floor known
and the views as ratios of means, the completed runs as a difference of rates. Then the lying
surfaces met (each run with a collision counted once per kind met) and the time per plan and per
insertion. Intervals: a count of runs gets the exact (Clopper-Pearson) 95 % interval; a mean, a
ratio or a difference the 95 % percentile bootstrap interval (worlds resampled; for the paired
comparisons the same worlds for both planners), each with a generator seeded by --seed and the
quantity's name, so that an interval does not move when other rows are added. With --charts DIR,
DIR/apartments_collisions.png and DIR/apartments_floor.png. Needs numpy (and matplotlib for
--charts).
"""
import argparse
import collections
import csv
import os
import sys
import zlib

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from bootstrap import clopper_pearson, mean_sd  # noqa: E402

PLANNERS = ["plain", "safe", "oracle"]
RIGS = {"eight": "eight cameras", "one": "one camera (differential drive)"}
UPDATES = ["interval-mean", "bayes"]
WORLDS = {"lying": "apartments", "honest": "honest twins"}
KINDS = ["wall-mirror", "half-mirror", "mirror-wardrobe", "mirror-cabinet", "free-mirror", "glass-partition",
         "glass-door", "glass-window", "black-furniture", "metal-panel"]


def rng_for(seed, name):
    return np.random.default_rng([seed, zlib.crc32(name.encode())])


def read_rows(path):
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    timings = os.path.join(os.path.dirname(path), "timings.csv")
    seconds = {}
    if os.path.exists(timings):
        with open(timings, newline="") as f:
            for t in csv.DictReader(f):
                seconds[(t["seed"], t["world"], t["planner"], t["rig"], t["update"])] = t
    for r in rows:
        for k in ("collision_poses", "collision_segments", "steps", "completed", "met_lying", "rooms"):
            r[k] = int(r[k])
        for k in ("known", "distance", "floor_area"):
            r[k] = float(r[k])
        r["collided"] = int(r["collision_poses"] > 0 or r["collision_segments"] > 0)
        t = seconds.get((r["seed"], r["world"], r["planner"], r["rig"], r["update"]))
        r["seconds_per_plan"] = float(t["seconds_per_plan"]) if t else float("nan")
        r["seconds_per_insert"] = float(t["seconds_per_insert"]) if t else float("nan")
        r["seconds_total"] = float(t["seconds_total"]) if t else float("nan")
    return rows


def rate(k, n):
    if n == 0:
        return "–"
    lo, hi = clopper_pearson(k, n)
    return f"{k} of {n} ({100 * k / n:.1f} %, {100 * lo:.1f}–{100 * hi:.1f})"


def boot_mean(v, name, args, scale=100.0, digits=1):
    v = np.asarray(v, dtype=float)
    if len(v) < 2:
        return mean_sd(v * scale, digits)
    rng = rng_for(args.seed, name)
    m = v[rng.integers(0, len(v), size=(args.resamples, len(v)))].mean(axis=1) * scale
    lo, hi = np.percentile(m, [2.5, 97.5])
    return f"{mean_sd(v * scale, digits)} ({lo:.{digits}f}–{hi:.{digits}f})"


def paired(a, b, stat, name, args, digits=2):
    """stat of the paired samples a, b (one per world) with its bootstrap interval (worlds resampled)."""
    a = np.asarray(a, dtype=float)
    b = np.asarray(b, dtype=float)
    if len(a) < 2:
        return "–"
    rng = rng_for(args.seed, name)
    idx = rng.integers(0, len(a), size=(args.resamples, len(a)))
    with np.errstate(divide="ignore", invalid="ignore"):
        d = stat(a[idx], b[idx])
        est = float(stat(a[None, :], b[None, :])[0])
    d = d[np.isfinite(d)]
    if len(d) == 0 or not np.isfinite(est):
        return "–"
    lo, hi = np.percentile(d, [2.5, 97.5])
    return f"{est:.{digits}f} ({lo:.{digits}f}–{hi:.{digits}f})"


def ratio_of_means(a, b):
    return a.mean(axis=1) / b.mean(axis=1)


def diff_of_means(a, b):
    return a.mean(axis=1) - b.mean(axis=1)


def cell(rows, world, planner, rig, update):
    return [r for r in rows if r["world"] == world and r["planner"] == planner and r["rig"] == rig and r["update"] == update]


def summary_table(rows, rig, update, args, out):
    out.append(f"| world | planner | runs with a collision | completed | floor known, % (mean ± sd, 95 % CI) | views (mean ± sd) "
               f"| floor known / oracle's | views / oracle's | completed − oracle's |")
    out.append("|---|---|---|---|---|---|---|---|---|")
    for world, wname in WORLDS.items():
        oracle = {r["seed"]: r for r in cell(rows, "lying", "oracle", rig, update)}
        for planner in PLANNERS:
            c = cell(rows, world, planner, rig, update)
            if not c:
                continue
            n = len(c)
            tag = f"{world}/{planner}/{rig}/{update}"
            known = boot_mean([r["known"] for r in c], tag + "/known", args)
            views = mean_sd(np.array([r["steps"] for r in c], dtype=float), 1)
            pairs = [(r, oracle[r["seed"]]) for r in c if r["seed"] in oracle]
            if pairs and planner != "oracle":
                k_rel = paired([p["known"] for p, _ in pairs], [o["known"] for _, o in pairs], ratio_of_means, tag + "/known-ratio", args)
                v_rel = paired([p["steps"] for p, _ in pairs], [o["steps"] for _, o in pairs], ratio_of_means, tag + "/views-ratio", args)
                c_rel = paired([p["completed"] for p, _ in pairs], [o["completed"] for _, o in pairs], diff_of_means,
                               tag + "/completed-diff", args)
            else:
                k_rel = v_rel = c_rel = "–"
            out.append(f"| {wname} | {planner} | {rate(sum(r['collided'] for r in c), n)} | {rate(sum(r['completed'] for r in c), n)} "
                       f"| {known} | {views} | {k_rel} | {v_rel} | {c_rel} |")


def kinds_table(rows, args, out):
    out.append("| rig | update | planner | runs | " + " | ".join(KINDS) + " | diffuse only |")
    out.append("|---|---|---|---|" + "---|" * (len(KINDS) + 1))
    for rig in RIGS:
        for update in UPDATES:
            for planner in PLANNERS:
                c = cell(rows, "lying", planner, rig, update)
                if not c:
                    continue
                met = collections.Counter()
                diffuse_only = 0
                for r in c:
                    if not r["collided"]:
                        continue
                    kinds = {m.split(":")[1] for m in r["met"].split(";") if ":" in m}
                    lying = kinds & set(KINDS)
                    for k in lying:
                        met[k] += 1
                    diffuse_only += 0 if lying else 1
                present = collections.Counter(k for r in c for k in r["kinds"].split(";") if k in KINDS)
                cells = [f"{met[k]}/{present[k]}" for k in KINDS]
                out.append(f"| {rig} | {update} | {planner} | {len(c)} | " + " | ".join(cells) + f" | {diffuse_only} |")


def timing_table(rows, out):
    out.append("| rig | update | planner | world | s per plan (mean ± sd) | s per insertion (mean ± sd) | s per run (mean ± sd) |")
    out.append("|---|---|---|---|---|---|---|")
    for rig in RIGS:
        for update in UPDATES:
            for world in WORLDS:
                for planner in PLANNERS:
                    c = cell(rows, world, planner, rig, update)
                    if not c:
                        continue
                    f = lambda k: mean_sd(np.array([r[k] for r in c], dtype=float), 3)  # noqa: E731
                    out.append(f"| {rig} | {update} | {planner} | {world} | {f('seconds_per_plan')} | {f('seconds_per_insert')} "
                               f"| {mean_sd(np.array([r['seconds_total'] for r in c], dtype=float), 1)} |")


def charts(rows, folder):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    os.makedirs(folder, exist_ok=True)
    cells = [(rig, update) for rig in RIGS for update in UPDATES]
    for what, name, ylabel in (("collided", "apartments_collisions.png", "runs with a collision, %"),
                               ("known", "apartments_floor.png", "reachable floor known, % (mean)")):
        fig, axes = plt.subplots(1, len(cells), figsize=(4.2 * len(cells), 4.0), sharey=True)
        for ax, (rig, update) in zip(np.atleast_1d(axes), cells):
            labels, values, colours, lows, highs = [], [], [], [], []
            for world in WORLDS:
                for planner in PLANNERS:
                    c = cell(rows, world, planner, rig, update)
                    if not c:
                        continue
                    labels.append(f"{planner}\n{'twin' if world == 'honest' else 'apt.'}\nn={len(c)}")
                    v = np.array([float(r[what]) for r in c])
                    values.append(100.0 * v.mean())
                    if what == "collided":  # exact binomial interval
                        lo, hi = clopper_pearson(int(v.sum()), len(v))
                    else:  # percentile bootstrap of the mean, seeded by the cell
                        rng = rng_for(1, f"chart/{what}/{world}/{planner}/{rig}/{update}")
                        m = v[rng.integers(0, len(v), size=(2000, len(v)))].mean(axis=1)
                        lo, hi = np.percentile(m, [2.5, 97.5])
                    lows.append(values[-1] - 100.0 * lo)
                    highs.append(100.0 * hi - values[-1])
                    colours.append({"plain": "#888888", "safe": "#1f77b4", "oracle": "#2ca02c"}[planner] if world == "lying" else "#cccccc")
            bars = ax.bar(range(len(values)), values, color=colours, edgecolor="black",
                          yerr=[lows, highs], capsize=3, error_kw={"elinewidth": 1})
            for b, v, h in zip(bars, values, highs):
                ax.text(b.get_x() + b.get_width() / 2 + 0.05, v + h + 1, f"{v:.0f}", ha="center", fontsize=8)
            ax.set_xticks(range(len(values)))
            ax.set_xticklabels(labels, fontsize=8)
            ax.set_title(f"{RIGS[rig]}\n{update}", fontsize=9)
            ax.set_ylim(0, 110)
        np.atleast_1d(axes)[0].set_ylabel(ylabel)
        fig.suptitle(f"Random apartments: {ylabel}, with 95 % intervals (twin: the same world, every surface diffuse)", fontsize=10)
        fig.tight_layout()
        fig.savefig(os.path.join(folder, name), dpi=110)
        plt.close(fig)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("results")
    ap.add_argument("--resamples", type=int, default=10000)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--charts", help="folder for the charts")
    args = ap.parse_args()
    if args.resamples < 100:
        ap.error("--resamples must be >= 100")
    rows = read_rows(args.results)
    if not rows:
        print("apartments_report: no rows", file=sys.stderr)
        return 1
    seeds = sorted({int(r["seed"]) for r in rows})
    out = ["# Random apartments: the report", "",
           f"{len(rows)} runs in {len(seeds)} worlds (seeds {seeds[0]}–{seeds[-1]}), from `{os.path.basename(args.results)}`. "
           "Intervals are 95 %: exact (Clopper–Pearson) for counts of runs, percentile bootstrap "
           f"({args.resamples} resamples of the worlds, seed {args.seed}) for means, ratios and differences.", ""]
    for rig, rname in RIGS.items():
        for update in UPDATES:
            if not any(r["rig"] == rig and r["update"] == update for r in rows):
                continue
            out += [f"## {rname}, {update}", ""]
            summary_table(rows, rig, update, args, out)
            out.append("")
    out += ["## Lying surfaces met", "",
            "Runs with a collision in which the robot met a lying surface of each kind (or the furniture it fronts), "
            "against the worlds holding that kind; 'diffuse only': runs with a collision that met no lying surface.", ""]
    kinds_table(rows, args, out)
    out += ["", "## Time", "", "Seconds of one core per plan and per insertion (sensing excluded), as timings.csv has them.", ""]
    timing_table(rows, out)
    print("\n".join(out))
    if args.charts:
        charts(rows, args.charts)
    return 0


if __name__ == "__main__":
    sys.exit(main())
