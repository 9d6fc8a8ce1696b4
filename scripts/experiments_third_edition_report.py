#!/usr/bin/env python3
"""The third edition's report from an experiments results.csv: the targets fixed before the runs
(docs/experiments.md, "Third edition: targets fixed before its runs"), each with its measured
value, its 95 % interval and whether it is met; then, per condition, every mobile configuration's
summary and the safe planner against the plain one.

Usage: experiments_third_edition_report.py RESULTS_CSV [--planted DIR] [--arm-normals CSV] [--resamples N] [--seed S]
       > report.md

Conditions: "thesis" (thesis presets, floor removed, gain over unknown voxels, the thesis' start
and map rules), "library" (clamped policies, every return inserted, gain over every voxel, the
library's start and map rules), "library, glint" (the same with the near-normal glint), "library,
body" (the same with the robot's own body, which a mirror shows) and "library, one camera" (the
same with one forward camera: target 9).
Closets: the lab room's diffuse, absorbing, transparent (glass) and specular (mirror) closets, the
mirror closet with the material on its front only (room front-only) and the diffuse closet with
the open door to the annex (room annex). Intervals: a count of runs gets the exact
(Clopper-Pearson) interval, a mean and a ratio or difference of means the 95 % percentile
bootstrap interval (groups resampled independently; each interval with a generator seeded by
--seed and its name, so that it does not change when rows are added to the file). Rows of other conditions (the
second edition's second conditions, the arm) are left to experiments_report.py. With --planted,
the summary lines of the planted scenes' runs (DIR/GRID-PLANNER.txt, planted_scenes' output: the
window, the symmetric rooms, the doorway to a deeper room) are tabled too; with --arm-normals,
target 10 from the polished part's runs (scripts/arm_normals_sweep.sh). With --charts DIR,
DIR/safe_vs_plain_collisions.png and safe_vs_plain_floor.png: per condition and update, the runs
with a collision and the floor known of both planners in every closet. Needs numpy (and matplotlib for --charts).
"""
import argparse
import csv
import os
import re
import sys
import zlib

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from bootstrap import bootstrap, bootstrap_mean, clopper_pearson, diff_of_means, mean_sd  # noqa: E402

CONDITIONS = {
    "thesis": dict(policies="thesis", floor="removed", gain="unknown", rules="thesis", sensor="plain"),
    "library": dict(policies="clamped", floor="kept", gain="all", rules="library", sensor="plain"),
    "library, glint": dict(policies="clamped", floor="kept", gain="all", rules="library", sensor="glint"),
    "library, body": dict(policies="clamped", floor="kept", gain="all", rules="library", sensor="body"),
    "library, one camera": dict(policies="clamped", floor="kept", gain="all", rules="library", sensor="one-camera"),
}
# (surface, room): the closets of the targets, in the order of the tables.
CLOSETS = [("diffuse", "lab"), ("absorbing", "lab"), ("transparent", "lab"), ("specular", "lab"),
           ("specular", "front-only"), ("diffuse", "annex")]
CLOSET_NAMES = {("diffuse", "lab"): "diffuse", ("absorbing", "lab"): "absorbing", ("transparent", "lab"): "glass",
                ("specular", "lab"): "mirror", ("specular", "front-only"): "front-only mirror",
                ("diffuse", "annex"): "diffuse, door to the annex"}
UPDATES = [("bayes", "entropy"), ("interval-mean", "max-entropy")]


def number(text, default=-1.0):
    return float(text) if text not in (None, "") else default


def load(path):
    """Mobile rows, with the columns the report reads parsed; the condition of each row, or None."""
    rows = []
    with open(path, newline="") as f:
        for r in csv.DictReader(f):
            if r["platform"] != "mobile":
                continue
            d = {k: r.get(k) or "" for k in ("surface", "update", "utility", "planner", "termination", "collision_objects")}
            d["room"] = r.get("room") or "lab"
            d["unobserved"] = r.get("unobserved") or "unknown"
            cond = {"policies": r["policies"], "floor": r["floor"], "gain": r["gain"], "rules": r.get("rules") or "thesis",
                    "sensor": r.get("sensor") or "plain"}
            d["condition"] = next((name for name, c in CONDITIONS.items() if c == cond), None)
            d["seed"] = int(r["seed"])
            d["steps"] = int(r["steps"])
            d["known"] = float(r["known"])
            d["completed"] = r["completed"] in ("1", "true", "True")
            d["collided"] = int(r["collision_poses"]) + int(r["collision_segments"]) > 0
            d["band_wrongly_free"] = int(r["band_wrongly_free"])
            d["band_voxels"] = int(r["band_voxels"])
            d["annex"] = number(r.get("annex_known"))
            d["distance"] = number(r.get("distance"))
            curve = r.get("closet_free_curve") or ""
            d["closet_curve"] = [float(x) for x in curve.split(";")] if curve else []
            for k in ("direct_suspect", "reflected_suspect", "suspect_precision", "suspect_recall", "explained_free_share",
                      "annex_explained_free_share", "door_plans", "door_opening_plans", "door_last_opening"):
                d[k] = number(r.get(k))
            rows.append(d)
    return rows


def group(rows, condition, surface, room, update, utility, planner):
    return [r for r in rows if r["condition"] == condition and r["surface"] == surface and r["room"] == room and
            r["update"] == update and r["utility"] == utility and r["planner"] == planner and r["unobserved"] == "unknown"]


def count_ci(k, n):
    lo, hi = clopper_pearson(k, n)
    return f"{k} of {n} ({100 * lo:.0f}–{100 * hi:.0f} %)"


def mean_ci(values, rng, resamples, digits, scale=1.0):
    v = np.asarray(values, dtype=float) * scale
    if len(v) == 0:
        return "–"
    b = bootstrap_mean(v, resamples, rng)
    if b is None:
        return f"{v.mean():.{digits}f}"
    return f"{b[0]:.{digits}f} [{b[1]:.{digits}f}, {b[2]:.{digits}f}]"


def ratio_of_means(a, b):
    mb = b.mean(axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(mb != 0, a.mean(axis=1) / mb, np.nan)


def objects_met(g):
    runs = {}
    for r in g:
        for item in filter(None, r["collision_objects"].split(";")):
            name = item.split("=")[0]
            runs[name] = runs.get(name, 0) + 1
    return ", ".join(f"{n} {runs[n]}" for n in sorted(runs, key=lambda n: (-runs[n], n))) or "–"


def collided_and_ended(safe, closets):
    """Per closet, the runs with a collision and the runs that ended before the budget (targets 5,
    6 and 9)."""
    return ({c: sum(r["collided"] for r in safe[c]) for c in closets},
            {c: sum(r["termination"] != "budget" for r in safe[c]) for c in closets})


def targets(rows, rng, resamples, arm=()):
    out = ["## Targets (fixed before the runs)", "",
           "| # | target | condition | update | measured | met |", "|---|---|---|---|---|---|"]
    missing = []
    for cond in ("thesis", "library"):
        for update, utility in UPDATES:
            safe = {c: group(rows, cond, c[0], c[1], update, utility, "safe") for c in CLOSETS}
            plain = {c: group(rows, cond, c[0], c[1], update, utility, "plain") for c in CLOSETS}
            five = [c for c in CLOSETS[:5] if safe[c]]
            if not five:
                missing.append(f"{cond}, {update}: no safe-planner rows")
                continue
            where = f"| {{}} | {{}} | {cond} | {update} + {utility} | {{}} | {{}} |"
            hit, ended = collided_and_ended(safe, five)
            # 5: no collision with the safe planner in any closet.
            cells = [f"{CLOSET_NAMES[c]} {count_ci(hit[c], len(safe[c]))}" for c in five]
            met = all(hit[c] == 0 for c in five)
            out.append(where.format(5, "0 runs with a collision (safe planner)", "; ".join(cells), "yes" if met else "**no**"))
            # 6: the episode ends before the budget in >= 9 of 10 runs per closet.
            cells = [f"{CLOSET_NAMES[c]} {count_ci(ended[c], len(safe[c]))}" for c in five]
            met = all(ended[c] >= 0.9 * len(safe[c]) for c in five)
            out.append(where.format(6, "completion (not the budget) in ≥ 9 of 10 runs", "; ".join(cells), "yes" if met else "**no**"))
            # 7: steps on the diffuse closet <= 1.25x the plain planner's.
            d = ("diffuse", "lab")
            if safe[d] and plain[d]:
                b = bootstrap([r["steps"] for r in safe[d]], [r["steps"] for r in plain[d]], ratio_of_means, resamples, rng('7', cond, update))
                if b:
                    out.append(where.format(7, "steps on the diffuse closet ≤ 1.25× plain",
                                            f"{b[0]:.2f}× [{b[1]:.2f}, {b[2]:.2f}] ({np.mean([r['steps'] for r in safe[d]]):.1f} "
                                            f"against {np.mean([r['steps'] for r in plain[d]]):.1f})",
                                            "yes" if b[0] <= 1.25 else "**no**"))
            # 8: >= 90 % of the annex floor known in >= 9 of 10 runs.
            a = ("diffuse", "annex")
            if safe[a]:
                k = sum(r["annex"] >= 0.9 for r in safe[a])
                out.append(where.format(8, "≥ 90 % of the annex floor known in ≥ 9 of 10 runs",
                                        f"{count_ci(k, len(safe[a]))}; annex known {mean_ci([r['annex'] for r in safe[a]], rng('8', cond, update), resamples, 1, 100)} %"
                                        + (f"; plain {sum(r['annex'] >= 0.9 for r in plain[a])} of {len(plain[a])}" if plain[a] else ""),
                                        "yes" if k >= 0.9 * len(safe[a]) else "**no**"))
            m = ("specular", "lab")
            if safe[m] and all(r["closet_curve"] for r in safe[m]):
                # 2: the mirror closet explained free <= 5 % at every planning step (its own voxels).
                worst = [max(r["closet_curve"]) for r in safe[m]]
                k = sum(w <= 0.05 for w in worst)
                out.append(where.format(2, "mirror closet: its voxels explained free ≤ 5 % at every step",
                                        f"runs within it {count_ci(k, len(worst))}; worst step per run "
                                        f"{mean_ci(worst, rng('2', cond, update), resamples, 1, 100)} %", "yes" if k == len(worst) else "**no**"))
            v = [r["reflected_suspect"] for r in safe[m] if r["reflected_suspect"] >= 0]
            if v:
                # 1: >= 90 % of the reflected beams suspect, over the runs whose ledger kept any.
                out.append(where.format(1, "mirror closet: ≥ 90 % of the reflected beams suspect",
                                        f"{mean_ci(v, rng('1', cond, update), resamples, 1, 100)} % of the kept reflected returns (the "
                                        f"{len(v)} of {len(safe[m])} runs whose ledger kept any)",
                                        "yes" if np.mean(v) >= 0.9 else "**no**"))
            if safe[d] and all(r["direct_suspect"] >= 0 for r in safe[d]):
                # 4 (first half): <= 2 % of the direct beams suspect in the diffuse room.
                v = [r["direct_suspect"] for r in safe[d]]
                out.append(where.format(4, "diffuse closet: ≤ 2 % of the direct beams suspect",
                                        f"{mean_ci(v, rng('4', cond, update), resamples, 2, 100)} % of the kept direct returns",
                                        "yes" if np.mean(v) <= 0.02 else "**no**"))
            if safe[d] and all(r["explained_free_share"] >= 0 for r in safe[d]):
                # 4 (second half): explained free >= 97 % of what plain insertion makes free (the
                # robot's band; the grid is the plain insertion, the channel explains).
                v = [r["explained_free_share"] for r in safe[d]]
                out.append(where.format("4b", "diffuse closet: explained free ≥ 97 % of the band plain insertion makes free",
                                        f"{mean_ci(v, rng('4b', cond, update), resamples, 1, 100)} %; runs at ≥ 97 % "
                                        f"{count_ci(sum(x >= 0.97 for x in v), len(v))}", "yes" if np.mean(v) >= 0.97 else "**no**"))
            if safe[a] and all(r["door_plans"] >= 0 for r in safe[a]):
                # 3: the doorway named an opening (by the last plan whose wall gaps held it) in >= 9 of 10 runs.
                k = sum(r["door_last_opening"] == 1 for r in safe[a])
                once = sum(r["door_opening_plans"] > 0 for r in safe[a])
                found = sum(r["door_plans"] > 0 for r in safe[a])
                beyond = [r["annex_explained_free_share"] for r in safe[a] if r["annex_explained_free_share"] >= 0]
                out.append(where.format(3, "annex door named an opening in ≥ 9 of 10 runs (the last plan that found its gap)",
                                        f"{count_ci(k, len(safe[a]))}; found by a plan in {found}, named an opening by any plan "
                                        f"in {once}; the annex's free band explained free "
                                        f"{mean_ci(beyond, rng('3', cond, update), resamples, 1, 100) if beyond else '–'} %",
                                        "yes" if k >= 0.9 * len(safe[a]) else "**no**"))
    one_camera = False
    for update, utility in UPDATES:
        # 9: one camera (library defaults): no collision and completion in >= 9 of 10 per closet.
        safe = {c: group(rows, "library, one camera", c[0], c[1], update, utility, "safe") for c in CLOSETS[:5]}
        five = [c for c in CLOSETS[:5] if safe[c]]
        if not five:
            continue
        one_camera = True
        hit, ended = collided_and_ended(safe, five)
        cells = [f"{CLOSET_NAMES[c]}: collision {count_ci(hit[c], len(safe[c]))}, ended {count_ci(ended[c], len(safe[c]))}"
                 for c in five]
        met = all(hit[c] == 0 and ended[c] >= 0.9 * len(safe[c]) for c in five)
        out.append(f"| 9 | one camera: 0 runs with a collision and completion in ≥ 9 of 10 runs (safe planner) | "
                   f"library, one camera | {update} + {utility} | {'; '.join(cells)} | {'yes' if met else '**no**'} |")
    out += list(arm)
    out += ["", "Not measured by the sweep: the window named *opening* (target 3 is measured at the annex's door)"
            + ("" if one_camera else "; target 9 needs the one-camera rows")
            + ("" if arm else "; target 10 needs --arm-normals") + "; see docs/experiments.md."]
    if missing:
        out += ["", "Missing: " + "; ".join(missing) + "."]
    return out


def summary(rows, cond, rng, resamples):
    out = [f"## Per configuration: {cond}", "",
           "| closet | update | planner | runs | runs with a collision | objects met (runs) | ended before the budget | "
           "completed | steps | m driven | floor known % | annex known % | band wrongly free % | closet free, worst step % | "
           "direct / reflected suspect % | suspect precision / recall |",
           "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for c in CLOSETS:
        for update, utility in UPDATES + [("interval-mean", "entropy")]:
            for planner in ("plain", "conflict-aware", "safe"):
                g = group(rows, cond, c[0], c[1], update, utility, planner)
                if not g:
                    continue
                n = len(g)
                annex = mean_sd([100 * r["annex"] for r in g], 1) if c[1] == "annex" else "–"
                band = mean_sd([100 * r["band_wrongly_free"] / r["band_voxels"] for r in g if r["band_voxels"] > 0], 1)
                worst = mean_sd([100 * max(r["closet_curve"]) for r in g if r["closet_curve"]], 1)
                direct = [100 * r["direct_suspect"] for r in g if r["direct_suspect"] >= 0]
                refl = [100 * r["reflected_suspect"] for r in g if r["reflected_suspect"] >= 0]
                sus = f"{mean_sd(direct, 2)} / {mean_sd(refl, 1)}" if direct or refl else "–"
                pr = "–"
                prec = [r["suspect_precision"] for r in g if r["suspect_precision"] >= 0]
                rec = [r["suspect_recall"] for r in g if r["suspect_recall"] >= 0]
                if prec or rec:
                    pr = f"{mean_sd(prec, 2) if prec else '–'} / {mean_sd(rec, 2) if rec else '–'}"
                out.append(f"| {CLOSET_NAMES[c]} | {update} + {utility} | {planner} | {n} | "
                           f"{count_ci(sum(r['collided'] for r in g), n)} | {objects_met(g)} | "
                           f"{sum(r['termination'] != 'budget' for r in g)} | {sum(r['completed'] for r in g)} | "
                           f"{mean_sd([r['steps'] for r in g], 1)} | {mean_sd([r['distance'] for r in g if r['distance'] >= 0], 1)} | "
                           f"{mean_sd([100 * r['known'] for r in g], 1)} | {annex} | "
                           f"{band} | {worst} | {sus} | {pr} |")
    return out


def safe_against_plain(rows, cond, rng, resamples):
    out = [f"## Safe − plain: {cond}", "",
           "| closet | update | steps | m driven | floor known (points) | band wrongly free (voxels) |", "|---|---|---|---|---|---|"]
    for c in CLOSETS:
        for update, utility in UPDATES:
            s = group(rows, cond, c[0], c[1], update, utility, "safe")
            p = group(rows, cond, c[0], c[1], update, utility, "plain")
            if not s or not p:
                continue
            cells = []
            for metric, k, digits in (("steps", 1, 1), ("distance", 1, 1), ("known", 100, 1), ("band_wrongly_free", 1, 0)):
                b = bootstrap([k * r[metric] for r in s], [k * r[metric] for r in p], diff_of_means, resamples,
                              rng('safe-plain', cond, c, update, metric))
                cells.append("–" if b is None else f"{b[0]:+.{digits}f} [{b[1]:+.{digits}f}, {b[2]:+.{digits}f}]")
            out.append(f"| {CLOSET_NAMES[c]} | {update} + {utility} | " + " | ".join(cells) + " |")
    return out


PLANTED = re.compile(r"^summary \| (?P<scene>[^|]+) \| runs with a collision (?P<hit>\d+) of (?P<n>\d+) \| "
                     r"ended before the budget (?P<ended>\d+) \| left the start room (?P<left>\d+) \| "
                     r"floor known (?P<known>[0-9.]+ ± [0-9.]+) %")


def planted(folder):
    """The planted scenes' summaries: one row per scene, update and planner, from the files
    GRID-PLANNER.txt of \p folder (GRID interval or bayes, PLANNER plain or safe)."""
    out = ["## The planted scenes (unbounded grids, 10 cm)", "",
           "| scene | update | planner | runs with a collision | ended before the budget | left the start room | floor known % |",
           "|---|---|---|---|---|---|---|"]
    rows = []
    for grid, update in (("interval", "interval-mean + max-entropy"), ("bayes", "bayes + entropy")):
        for planner in ("plain", "safe"):
            path = os.path.join(folder, f"{grid}-{planner}.txt")
            if not os.path.exists(path):
                continue
            with open(path, encoding="utf-8") as f:
                for line in f:
                    m = PLANTED.match(line.strip())
                    if m:
                        rows.append((m["scene"].strip(), update, planner, m))
    for scene, update, planner, m in sorted(rows, key=lambda r: r[0]):
        out.append(f"| {scene} | {update} | {planner} | {count_ci(int(m['hit']), int(m['n']))} | {m['ended']} | {m['left']} | "
                   f"{m['known']} |")
    return out if rows else []


def arm_target(path, rng, resamples):
    """Target 10 from the polished part's runs (scripts/arm_normals_sweep.sh's CSV): the explained
    model with views that seek normals, per update."""
    with open(path, newline="") as f:
        rows = [r for r in csv.DictReader(f) if r["normals"] == "on"]
    out = []
    for update in ("interval-mean", "dirichlet-mean", "bayes"):
        g = [r for r in rows if r["update"] == update]
        if not g:
            continue
        # Reached within the 12-view budget: the sweep's first view whose model holds 80 % (0: never).
        k = sum(int(r["views_to_80_model"]) > 0 for r in g)
        wrong = [float(r["model_wrongly_occupied"]) for r in g]
        met = k >= 0.8 * len(g) and np.mean(wrong) <= 108
        out.append(f"| 10 | polished part: ≥ 80 % of its visible surface within 12 views in ≥ 8 of 10 runs (explained model, normals sought); "
                   f"wrongly occupied ≤ 108 | arm | {update} | {count_ci(k, len(g))}; coverage "
                   f"{mean_ci([float(r['model_coverage_percent']) for r in g], rng('10', update, 'coverage'), resamples, 1)} %; wrongly occupied "
                   f"{mean_ci(wrong, rng('10', update, 'wrong'), resamples, 0)} | {'yes' if met else '**no**'} |")
    return out


CHART_CONDITIONS = ["thesis", "library", "library, glint", "library, body", "library, one camera"]


def chart(rows, path, metric):
    """The plain and the safe planner in every closet: runs with a collision (metric "collisions",
    the count written on each bar) or the floor known (metric "floor", mean ± sd); one row of
    panels per condition that has safe rows, one column per update."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    conds = [c for c in CHART_CONDITIONS
             if any(group(rows, c, s, room, u, h, "safe") for s, room in CLOSETS for u, h in UPDATES)]
    if not conds:
        return False
    fig, axes = plt.subplots(len(conds), len(UPDATES), figsize=(10, 2.3 * len(conds) + 1.2), sharex=True, sharey=True,
                             squeeze=False)
    colours = {"plain": "#d62728", "safe": "#2ca02c"}
    names = [CLOSET_NAMES[c].replace(", door to the annex", " + annex") for c in CLOSETS]
    for i, cond in enumerate(conds):
        for j, (update, utility) in enumerate(UPDATES):
            ax = axes[i][j]
            drawn = False
            for k, planner in enumerate(("plain", "safe")):
                xs, ys, sd = [], [], []
                for x, (s, room) in enumerate(CLOSETS):
                    g = group(rows, cond, s, room, update, utility, planner)
                    if not g:
                        continue
                    xs.append(x - 0.2 + 0.4 * k)
                    if metric == "collisions":
                        ys.append(sum(r["collided"] for r in g))
                    else:
                        v = np.array([r["known"] * 100 for r in g])
                        ys.append(v.mean())
                        sd.append(v.std(ddof=1) if len(v) > 1 else 0.0)
                if not xs:
                    continue
                drawn = True
                bars = ax.bar(xs, ys, 0.4, yerr=sd or None, capsize=2, color=colours[planner], label=f"{planner} planner")
                if metric == "collisions":
                    ax.bar_label(bars, fontsize=7, padding=1)
            ax.set_title(f"{cond}: {update} + {utility}", fontsize=9)
            ax.set_ylim(0, 11.5 if metric == "collisions" else 110)
            ax.grid(axis="y", alpha=0.3)
            ax.set_xticks(range(len(CLOSETS)), names, rotation=30, ha="right", fontsize=8)
            if not drawn:
                ax.text(0.5, 0.5, "not run", transform=ax.transAxes, ha="center", va="center", color="0.5")
        axes[i][0].set_ylabel("runs with a collision\n(of 10)" if metric == "collisions" else "floor known, %\n(mean ± sd)",
                              fontsize=8)
    handles, labels = [], []
    for ax in axes.flat:
        for h, lab in zip(*ax.get_legend_handles_labels()):
            if lab not in labels:
                handles.append(h)
                labels.append(lab)
    fig.legend(handles, labels, loc="lower center", ncol=2, frameon=False)
    fig.suptitle(("Runs with a collision" if metric == "collisions" else "Reachable floor known at the end")
                 + ", plain and safe planner, 10 seeds per closet", fontsize=11)
    fig.tight_layout(rect=(0, 0.04, 1, 0.98))
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return True


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("csv")
    ap.add_argument("--planted", help="folder of the planted scenes' outputs (GRID-PLANNER.txt)")
    ap.add_argument("--arm-normals", help="scripts/arm_normals_sweep.sh's CSV of the polished part (target 10)")
    ap.add_argument("--charts", help="folder for safe_vs_plain_collisions.png and _floor.png (needs matplotlib)")
    ap.add_argument("--resamples", type=int, default=10000)
    ap.add_argument("--seed", type=int, default=16)
    a = ap.parse_args(argv)
    rows = load(a.csv)
    # Every interval resamples with a generator of its own, seeded by --seed and the interval's
    # name: an interval does not change when other rows are added to the file.
    def rng(*key):
        return np.random.default_rng([a.seed] + [zlib.crc32(str(k).encode()) for k in key])
    lines = ["# Experiments, third edition: report", "",
             f"From `{os.path.basename(a.csv)}`: {len(rows)} mobile runs. Counts of runs with their exact 95 % "
             "interval; means and ratios with their 95 % percentile bootstrap interval "
             f"({a.resamples} resamples, seed {a.seed}).", ""]
    lines += targets(rows, rng, a.resamples, arm_target(a.arm_normals, rng, a.resamples) if a.arm_normals else [])
    for cond in CONDITIONS:
        if any(r["condition"] == cond for r in rows):
            lines += [""] + summary(rows, cond, rng, a.resamples) + [""] + safe_against_plain(rows, cond, rng, a.resamples)
    if a.planted:
        lines += [""] + planted(a.planted)
    if a.charts:
        os.makedirs(a.charts, exist_ok=True)
        for metric, title in (("collisions", "runs with a collision"), ("floor", "floor known")):
            if chart(rows, os.path.join(a.charts, f"safe_vs_plain_{metric}.png"), metric):
                lines += ["", f"![Safe and plain planner: {title}](charts/safe_vs_plain_{metric}.png)"]
    print("\n".join(lines))
    return 0


if __name__ == "__main__":
    sys.exit(main())
