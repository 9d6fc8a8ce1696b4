#!/usr/bin/env python3
"""The second edition's report from an experiments results.csv: the targets of the experiments
issue with their measured values, the comparisons behind the seven verdicts, each a difference of
means with a 95 % percentile bootstrap interval (seeded, groups resampled independently), and the
charts (matplotlib) of the second edition (docs/notes/experiments-second-edition.md, in short in
docs/experiments.md). For the arm it adds the share of the voxels classified
occupied that are wrong, per run; for the thesis condition, the second conditions' differences
from it (latching off, gain over every voxel), configuration by configuration.

Usage: experiments_report.py RESULTS_CSV --charts DIR [--policies thesis] [--floor removed]
                             [--gain unknown] [--resamples N] [--seed S] > report.md

Rows are selected by condition (policy preset, floor handling, gain rule; of the third edition's
rows only those of the lab room, the thesis' start and map rules and the plain sensor); within a condition a
configuration is named by its platform, surface, update, criterion, planner and classification
of never-observed space. Configurations that are missing from the file are left out of the tables
and charts (a line says which). Needs numpy and matplotlib (Debian: python3-numpy,
python3-matplotlib).
"""
import argparse
import csv
import math
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from bootstrap import bootstrap, bootstrap_mean, diff_of_means, mean_sd, relative_reduction  # noqa: E402

INT_COLUMNS = ("steps", "wrongly_occupied", "wrongly_free", "band_wrongly_occupied", "band_wrongly_free",
               "band_voxels", "region_voxels", "collision_poses", "collision_segments", "views_to_80")
SURFACES = ("diffuse", "absorbing", "transparent", "specular")
# Visible surface voxels of the arm's objects at the sweep's 1 cm (surface_coverage: occupied voxels
# of the object region with a face neighbour free in the scene above the table top), of the
# region's 624 (part) and 1268 (bottle) occupied voxels (the rows' true_occupied). The coverage
# column is a count of these divided by them; occupied_share() checks that it is (it is not for
# another voxel size or a hand-made file, and the share is then left out).
SURFACE_VOXELS = {"part": 336, "bottle": 532}
ORDER = SURFACES + ("specular-random", "part", "bottle")


def parse_objects(text):
    """collision_objects ("name=poses/segments;..."): {name: (poses, segments)}."""
    out = {}
    for item in filter(None, (text or "").split(";")):
        name, counts = item.split("=")
        poses, segments = counts.split("/")
        out[name] = (int(poses), int(segments))
    return out


def load(path, policies, floor, gain):
    """Rows of the condition, with numbers parsed and derived columns added."""
    rows = []
    with open(path, newline="") as f:
        for r in csv.DictReader(f):
            if r["policies"] != policies or r["gain"] != gain:
                continue
            if r["platform"] == "mobile" and r["floor"] != floor:
                continue
            # The third edition's rooms, start and map rules and sensor conditions have their own
            # report (experiments_third_edition_report.py); this one reads the lab room, the
            # thesis' rules and the plain sensor (every row of earlier files).
            if (r.get("room") or "lab") != "lab" or (r.get("rules") or "thesis") != "thesis" or (r.get("sensor") or "plain") != "plain":
                continue
            d = dict(r)
            for k in INT_COLUMNS:
                d[k] = int(r[k])
            d["known"] = float(r["known"])
            d["completed"] = r["completed"] in ("1", "true", "True")
            d["collided"] = d["collision_poses"] + d["collision_segments"] > 0
            d["objects"] = parse_objects(r["collision_objects"]) if "collision_objects" in r else None
            d["unobserved"] = r.get("unobserved", "unknown") or "unknown"
            curve = r.get("coverage_curve", "")
            d["curve"] = [float(x) for x in curve.split(";")] if curve else []
            rows.append(d)
    return rows


def config(platform, surface, update, utility, planner="plain", unobserved="unknown"):
    return (platform, surface, update, utility, planner, unobserved)


def key_of(r):
    return config(r["platform"], r["surface"], r["update"], r["utility"], r["planner"], r["unobserved"])


def label(c):
    """Short name of a configuration within a platform and surface."""
    _, _, update, utility, planner, unobserved = c
    s = f"{update} + {utility}"
    if unobserved != "unknown":
        s += " (unobserved by rule)"
    if planner != "plain":
        s += f", {planner}"
    return s


class Report:
    def __init__(self, rows, resamples, seed):
        self.groups = {}
        for r in rows:
            self.groups.setdefault(key_of(r), []).append(r)
        self.resamples = resamples
        self.rng = np.random.default_rng(seed)
        self.missing = set()

    def get(self, c):
        g = self.groups.get(c)
        if not g:
            self.missing.add(c)
        return g

    def values(self, c, metric):
        g = self.get(c)
        return None if not g else np.array([float(metric(r)) if callable(metric) else float(r[metric]) for r in g])

    def compare(self, a, b, metric, stat=diff_of_means):
        va, vb = self.values(a, metric), self.values(b, metric)
        if va is None or vb is None:
            return None
        return bootstrap(va, vb, stat, self.resamples, self.rng)

    def mean_ci(self, c, metric):
        v = self.values(c, metric)
        return None if v is None else bootstrap_mean(v, self.resamples, self.rng)


def fmt_ci(res, digits, percent=False):
    if res is None:
        return "–", "–"
    k = 100 if percent else 1
    unit = " %" if percent else ""
    v, lo, hi = (x * k for x in res)
    return f"{v:+.{digits}f}{unit}", f"[{lo:+.{digits}f}, {hi:+.{digits}f}]{unit}"


def targets(rep):
    """The experiments issue's targets, fixed before the runs, with what was measured."""
    ca = config("mobile", "specular", "interval-mean", "max-entropy", "conflict-aware")
    plain = config("mobile", "specular", "interval-mean", "max-entropy", "plain")
    arm_ca = config("arm", "part", "interval-mean", "max-entropy", "conflict-aware")
    out = ["| target (fixed before the runs) | measured | 95 % CI | met |", "|---|---|---|---|"]
    g_ca, g_plain = rep.get(ca), rep.get(plain)
    if g_ca and g_plain:
        done = sum(r["completed"] for r in g_ca)
        out.append(f"| mirror closet, conflict-aware interval-mean: completes ≥ 9 of 10 runs | {done} of {len(g_ca)} "
                   f"(plain: {sum(r['completed'] for r in g_plain)} of {len(g_plain)}) | – | "
                   f"{'yes' if done >= 0.9 * len(g_ca) else 'no'} |")
        for metric, name in (("steps", "≥ 30 % fewer steps than plain interval-mean + max-entropy"),
                             ("band_wrongly_occupied", "≥ 30 % fewer wrongly occupied voxels in the closet band")):
            res = rep.compare(ca, plain, metric, relative_reduction)
            v, ci = fmt_ci(res, 1, percent=True)
            ma, mb = np.mean(rep.values(ca, metric)), np.mean(rep.values(plain, metric))
            measured = f"reduction {v} ({ma:.1f} vs {mb:.1f})"
            met = "–" if res is None else ("yes" if res[0] >= 0.3 else "no")
            if ma == 0 and mb == 0:
                measured, met = f"none: 0 in every run of both ({ma:.1f} vs {mb:.1f})", "not measurable"
            out.append(f"| mirror closet: {name} | {measured} | {ci} | {met} |")
        hits = sum(r["collided"] for r in g_ca)
        out.append(f"| mirror closet, conflict-aware: zero runs with a collision | {hits} of {len(g_ca)} "
                   f"(plain: {sum(r['collided'] for r in g_plain)} of {len(g_plain)}) | – | {'yes' if hits == 0 else 'no'} |")
    g_arm = rep.get(arm_ca)
    if g_arm:
        reached = [r for r in g_arm if 0 <= r["views_to_80"] <= 12]
        res = rep.mean_ci(arm_ca, lambda r: r["known"] * 100)
        ci = "–" if res is None else f"[{res[1]:.1f}, {res[2]:.1f}] %"
        out.append(f"| arm, polished part, conflict-aware: ≥ 80 % of its visible surface within 12 views | "
                   f"{len(reached)} of {len(g_arm)} runs; coverage after the last view "
                   f"{mean_sd([r['known'] * 100 for r in g_arm], 1)} % | {ci} | {'yes' if len(reached) == len(g_arm) else 'no'} |")
    if len(out) == 2:
        out.append("| (the targets' configurations have no runs in this condition) | – | – | – |")
    return out


def occupied_share(r):
    """Arm: wrongly occupied / (wrongly occupied + visible surface voxels classified occupied), the
    latter coverage x SURFACE_VOXELS. The object's voxels off its visible surface classified
    occupied are not in the rows, so the share over all the region's occupied voxels is at most this. None where nothing
    is classified occupied; ValueError if the coverage is not a count of SURFACE_VOXELS."""
    n = SURFACE_VOXELS[r["surface"]]
    known = r["known"] * n
    if abs(known - round(known)) > 1e-6:
        raise ValueError(f"{r['surface']} coverage {r['known']} (seed {r['seed']}) is not a count of {n} voxels")
    total = r["wrongly_occupied"] + round(known)
    return None if total == 0 else r["wrongly_occupied"] / total


def occupied_share_table(rep):
    """Arm configurations: the share of the voxels classified occupied that are wrong (mean +- sd
    over the runs, 95 % bootstrap interval of the mean), and interval-mean - Bayes."""
    out = ["| object | configuration | runs | voxels counted as classified occupied | of them wrongly occupied | share wrong | 95 % CI of the mean |",
           "|---|---|---|---|---|---|---|"]
    arm = sorted((c for c in rep.groups if c[0] == "arm" and c[1] in SURFACE_VOXELS),
                 key=lambda c: (ORDER.index(c[1]), c[2], c[3], c[4], c[5]))
    try:
        for c in arm:
            for r in rep.groups[c]:
                occupied_share(r)
    except ValueError as e:
        return [f"Left out: {e}."]
    for c in arm:
        g = [r for r in rep.groups[c] if occupied_share(r) is not None]
        if not g:
            continue
        shares = [occupied_share(r) for r in g]
        counted = [r["wrongly_occupied"] + round(r["known"] * SURFACE_VOXELS[r["surface"]]) for r in g]
        res = bootstrap_mean(shares, rep.resamples, rep.rng)
        ci = "–" if res is None else f"[{res[1]:.2f}, {res[2]:.2f}]"
        left = len(rep.groups[c]) - len(g)
        runs = f"{len(g)}" + (f" ({left} with none classified occupied left out)" if left else "")
        out.append(f"| {c[1]} | {label(c)} | {runs} | {mean_sd(counted, 0)} | {mean_sd([r['wrongly_occupied'] for r in g], 0)} | "
                   f"{mean_sd(shares, 2)} | {ci} |")
    if len(out) == 2:
        return []
    out += ["", "| comparison | a − b | 95 % CI |", "|---|---|---|"]
    for o in SURFACE_VOXELS:
        for u in ("entropy", "max-entropy"):
            a, b = config("arm", o, "interval-mean", u), config("arm", o, "bayes", "entropy")
            if not rep.groups.get(a) or not rep.groups.get(b):
                continue
            va = [x for x in (occupied_share(r) for r in rep.groups[a]) if x is not None]
            vb = [x for x in (occupied_share(r) for r in rep.groups[b]) if x is not None]
            v, ci = fmt_ci(bootstrap(va, vb, diff_of_means, rep.resamples, rep.rng), 2)
            out.append(f"| arm, {o}: share wrong, interval-mean + {u} − bayes + entropy | {v} | {ci} |")
    return out


def second_conditions(rep, path, policies, floor, gain):
    """The second conditions against the report's one, configuration by configuration: the same
    configuration with one option changed (policies thesis -> clamped, gain unknown -> all), second
    minus this one, for steps and wrongly occupied voxels."""
    out = ["| second condition | configuration | metric | this condition | second condition | second − this | 95 % CI |",
           "|---|---|---|---|---|---|---|"]
    others = []
    if policies == "thesis":
        others.append(("clamped policies", load(path, "clamped", floor, gain)))
    if gain == "unknown":
        others.append(("gain over all voxels", load(path, policies, floor, "all")))
    order = {s: i for i, s in enumerate(ORDER)}
    for name, rows in others:
        groups = {}
        for r in rows:
            groups.setdefault(key_of(r), []).append(r)
        for c in sorted(groups, key=lambda c: (c[0] != "mobile", order.get(c[1], 99), c[2], c[3], c[4], c[5])):
            mine = rep.groups.get(c)
            if not mine:
                continue
            for metric, digits in (("steps", 1), ("wrongly_occupied", 0)):
                va = [float(r[metric]) for r in groups[c]]
                vb = [float(r[metric]) for r in mine]
                v, ci = fmt_ci(bootstrap(va, vb, diff_of_means, rep.resamples, rep.rng), digits)
                out.append(f"| {name} | {c[0]}, {c[1]}, {label(c)} | {metric.replace('_', ' ')} | {mean_sd(vb, digits)} | "
                           f"{mean_sd(va, digits)} | {v} | {ci} |")
    return out if len(out) > 2 else []


def comparisons():
    """(claim, what, configuration a, configuration b, metric, digits): a - b is reported."""
    m = lambda s, u, h, **k: config("mobile", s, u, h, **k)  # noqa: E731
    a = lambda o, u, h, **k: config("arm", o, u, h, **k)  # noqa: E731
    share = lambda col, n: (lambda r: r[col] / r[n] * 100)  # noqa: E731
    out = []
    for s in SURFACES:
        out.append((1 if s == "diffuse" else 4 if s == "specular" else 2 if s == "absorbing" else 3,
                    f"{s}: steps, interval-mean + entropy − bayes + entropy",
                    m(s, "interval-mean", "entropy"), m(s, "bayes", "entropy"), "steps", 1))
    out.append((1, "diffuse: steps, interval-mean + max-entropy − bayes + entropy", m("diffuse", "interval-mean", "max-entropy"),
                m("diffuse", "bayes", "entropy"), "steps", 1))
    for s in ("absorbing", "transparent", "specular"):
        for u, h in (("bayes", "entropy"), ("interval-mean", "entropy")):
            out.append((2 if s == "absorbing" else 3 if s == "transparent" else 4,
                        f"{u} + {h}: band wrongly free % of band, {s} − diffuse",
                        m(s, u, h), m("diffuse", u, h), share("band_wrongly_free", "band_voxels"), 2))
    out.append((4, "specular-random: steps, interval-mean + max-entropy − bayes + entropy",
                m("specular-random", "interval-mean", "max-entropy"), m("specular-random", "bayes", "entropy"), "steps", 1))
    out.append((4, "specular-random: wrongly occupied, interval-mean + max-entropy − bayes + entropy",
                m("specular-random", "interval-mean", "max-entropy"), m("specular-random", "bayes", "entropy"),
                "wrongly_occupied", 0))
    for s in ("diffuse", "specular"):
        out.append((5, f"{s}: steps, interval-lower (by rule) − interval-mean, max-entropy",
                    m(s, "interval-lower", "max-entropy", unobserved="by-rule"), m(s, "interval-mean", "max-entropy"), "steps", 1))
        out.append((5, f"{s}: steps, interval-upper (by rule) − interval-mean, max-entropy",
                    m(s, "interval-upper", "max-entropy", unobserved="by-rule"), m(s, "interval-mean", "max-entropy"), "steps", 1))
        out.append((5, f"{s}: wrongly occupied, interval-upper (by rule) − interval-mean, max-entropy",
                    m(s, "interval-upper", "max-entropy", unobserved="by-rule"), m(s, "interval-mean", "max-entropy"),
                    "wrongly_occupied", 0))
        out.append((5, f"{s}: wrongly free, interval-lower (by rule) − interval-mean, max-entropy",
                    m(s, "interval-lower", "max-entropy", unobserved="by-rule"), m(s, "interval-mean", "max-entropy"),
                    "wrongly_free", 0))
        for u, col, d in (("interval-lower", "steps", 1), ("interval-upper", "steps", 1),
                          ("interval-upper", "wrongly_occupied", 0), ("interval-lower", "wrongly_free", 0)):
            out.append((5, f"{s}: {col.replace('_', ' ')}, {u} (unobserved unknown) − interval-mean, max-entropy",
                        m(s, u, "max-entropy"), m(s, "interval-mean", "max-entropy"), col, d))
    for s in SURFACES:
        out.append((6, f"{s}: steps, interval-mean + max-entropy − interval-mean + entropy",
                    m(s, "interval-mean", "max-entropy"), m(s, "interval-mean", "entropy"), "steps", 1))
        out.append((6, f"{s}: steps, interval-mean + max-entropy − bayes + entropy",
                    m(s, "interval-mean", "max-entropy"), m(s, "bayes", "entropy"), "steps", 1))
    for o in ("part", "bottle"):
        out.append((7, f"arm, {o}: wrongly occupied, interval-mean − bayes (entropy)", a(o, "interval-mean", "entropy"),
                    a(o, "bayes", "entropy"), "wrongly_occupied", 0))
        out.append((7, f"arm, {o}: wrongly free, interval-mean − bayes (entropy)", a(o, "interval-mean", "entropy"),
                    a(o, "bayes", "entropy"), "wrongly_free", 0))
        out.append((7, f"arm, {o}: coverage %, interval-mean − bayes (entropy)", a(o, "interval-mean", "entropy"),
                    a(o, "bayes", "entropy"), lambda r: r["known"] * 100, 1))
    out.append((7, "arm, part: coverage %, interval-mean conflict-aware − plain (max-entropy)",
                a("part", "interval-mean", "max-entropy", planner="conflict-aware"), a("part", "interval-mean", "max-entropy"),
                lambda r: r["known"] * 100, 1))
    for s in SURFACES + ("specular-random",):
        for col, d in (("steps", 1), ("band_wrongly_free", 0), ("collision_poses", 1)):
            out.append((0, f"{s}: {col.replace('_', ' ')}, interval-mean + max-entropy conflict-aware − plain",
                        m(s, "interval-mean", "max-entropy", planner="conflict-aware"), m(s, "interval-mean", "max-entropy"),
                        col, d))
    return out


def summary_table(rep):
    """Per configuration: runs, completed, steps, known, errors, band errors, collisions, terminations."""
    out = ["| platform | surface | configuration | runs | completed | steps | known % | wrongly occupied | "
           "wrongly free | band wrongly occupied | band wrongly free | runs with a collision | terminations |",
           "|---" * 13 + "|"]
    order = {s: i for i, s in enumerate(ORDER)}
    for c in sorted(rep.groups, key=lambda c: (c[0] != "mobile", order.get(c[1], 99), c[2], c[3], c[4], c[5])):
        g = rep.groups[c]
        terms = {}
        for r in g:
            terms[r["termination"]] = terms.get(r["termination"], 0) + 1
        band = c[0] == "mobile"
        out.append(f"| {c[0]} | {c[1]} | {label(c)} | {len(g)} | {sum(r['completed'] for r in g)} | "
                   f"{mean_sd([r['steps'] for r in g], 1)} | {mean_sd([r['known'] * 100 for r in g], 1)} | "
                   f"{mean_sd([r['wrongly_occupied'] for r in g], 0)} | {mean_sd([r['wrongly_free'] for r in g], 0)} | "
                   f"{mean_sd([r['band_wrongly_occupied'] for r in g], 0) if band else '–'} | "
                   f"{mean_sd([r['band_wrongly_free'] for r in g], 0) if band else '–'} | "
                   f"{sum(r['collided'] for r in g) if band else '–'} | "
                   + ", ".join(f"{k} {v}" for k, v in sorted(terms.items())) + " |")
    return out


def collision_table(rep):
    """Mobile configurations with a collision: the scene objects met, with the runs that met each
    and their poses in collision. Empty if the file has no collision_objects column."""
    out = ["| surface | configuration | runs with a collision | objects met: runs (poses in collision, sum over the runs) |",
           "|---|---|---|---|"]
    order = {s: i for i, s in enumerate(ORDER)}
    for c in sorted(rep.groups, key=lambda c: (order.get(c[1], 99), c[2], c[3], c[4], c[5])):
        g = rep.groups[c]
        if c[0] != "mobile" or any(r["objects"] is None for r in g) or not any(r["collided"] for r in g):
            continue
        runs, poses = {}, {}
        for r in g:
            for name, (p, sgm) in r["objects"].items():
                runs[name] = runs.get(name, 0) + 1
                poses[name] = poses.get(name, 0) + p
        met = ", ".join(f"{n} {runs[n]} ({poses[n]})" for n in sorted(runs, key=lambda n: (-runs[n], n)))
        out.append(f"| {c[1]} | {label(c)} | {sum(r['collided'] for r in g)} of {len(g)} | {met} |")
    return out if len(out) > 2 else []


# ---------------------------------------------------------------------------------------------
# Charts

MOBILE_BARS = [  # (configuration without the surface, legend, colour)
    (("bayes", "entropy", "plain", "unknown"), "Bayes + entropy", "#4d4d4d"),
    (("interval-mean", "entropy", "plain", "unknown"), "interval-mean + entropy", "#1f77b4"),
    (("interval-mean", "max-entropy", "plain", "unknown"), "interval-mean + max-entropy", "#6baed6"),
    (("interval-lower", "max-entropy", "plain", "by-rule"), "interval-lower + max-entropy (by rule)", "#2ca02c"),
    (("interval-upper", "max-entropy", "plain", "by-rule"), "interval-upper + max-entropy (by rule)", "#d62728"),
    (("interval-lower", "max-entropy", "plain", "unknown"), "interval-lower + max-entropy", "#98df8a"),
    (("interval-upper", "max-entropy", "plain", "unknown"), "interval-upper + max-entropy", "#ff9896"),
    (("interval-mean", "max-entropy", "conflict-aware", "unknown"), "interval-mean + max-entropy, conflict-aware", "#9467bd"),
]


def bar_chart(rep, metric, ylabel, title, path, plt, count=False):
    """Grouped bars per closet surface: mean with sd error bars (or a count of runs with \\p count)."""
    fig, ax = plt.subplots(figsize=(10, 5.6))
    width = 0.8 / len(MOBILE_BARS)
    drawn = False
    for j, (rest, name, colour) in enumerate(MOBILE_BARS):
        xs, ys, es = [], [], []
        for i, s in enumerate(SURFACES):
            g = rep.groups.get(("mobile", s) + rest)
            if not g:
                continue
            v = np.array([float(metric(r)) for r in g])
            xs.append(i - 0.4 + (j + 0.5) * width)
            ys.append(v.sum() if count else v.mean())
            es.append(0 if count or len(v) < 2 else v.std(ddof=1))
        if xs:
            drawn = True
            ax.bar(xs, ys, width, yerr=None if count else es, capsize=2, color=colour, label=name)
    ax.set_xticks(range(len(SURFACES)), [f"{s} closet" for s in SURFACES])
    ax.set_ylabel(ylabel)
    ax.set_title(title)
    ax.grid(axis="y", alpha=0.3)
    if drawn:
        ax.legend(fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.08), ncol=3, frameon=False)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def coverage_chart(rep, path, plt):
    fig, axes = plt.subplots(1, 2, figsize=(10, 4.8), sharey=True)
    # The conflict-aware line dashed: where it equals the plain one, both stay visible.
    styles = [(("bayes", "entropy", "plain", "unknown"), "Bayes + entropy", "#4d4d4d", "-"),
              (("interval-mean", "max-entropy", "plain", "unknown"), "interval-mean + max-entropy", "#1f77b4", "-"),
              (("interval-mean", "max-entropy", "conflict-aware", "unknown"), "interval-mean + max-entropy, conflict-aware",
               "#9467bd", "--")]
    for ax, obj in zip(axes, ("part", "bottle")):
        for rest, name, colour, line in styles:
            g = rep.groups.get(("arm", obj) + rest)
            if not g:
                continue
            n = max(len(r["curve"]) for r in g)
            # A run that ended early keeps its last coverage for the remaining views.
            c = np.array([r["curve"] + [r["curve"][-1]] * (n - len(r["curve"])) for r in g if r["curve"]]) * 100
            x = np.arange(1, n + 1)
            mean = c.mean(axis=0)
            sd = c.std(axis=0, ddof=1) if len(c) > 1 else np.zeros(n)
            ax.plot(x, mean, color=colour, ls=line, label=f"{name} ({len(c)} runs)")
            ax.fill_between(x, mean - sd, mean + sd, color=colour, alpha=0.2)
        ax.axhline(80, color="k", ls="--", lw=0.8)
        ax.text(12, 81, "80 % target", fontsize=8, ha="right")
        ax.set_title({"part": "polished part", "bottle": "glass bottle"}[obj])
        ax.set_xlabel("views (the first included)")
        ax.set_ylim(0, 100)
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("visible surface known occupied, % (mean ± sd)")
    handles, labels = [], []
    for ax in axes:
        for h, lab in zip(*ax.get_legend_handles_labels()):
            if lab.split(" (")[0] not in [x.split(" (")[0] for x in labels]:
                handles.append(h)
                labels.append(lab.split(" (")[0])
    if handles:
        fig.legend(handles, labels, fontsize=8, loc="lower center", ncol=3, frameon=False)
    fig.tight_layout(rect=(0, 0.07, 1, 1))
    fig.savefig(path, dpi=110)
    plt.close(fig)


def charts(rep, out):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    os.makedirs(out, exist_ok=True)
    written = []

    def bar(name, *a, **k):
        bar_chart(rep, *a, os.path.join(out, name), plt, **k)
        written.append(name)

    bar("steps.png", lambda r: r["steps"], "steps after the look-around (mean ± sd)",
        "Steps per update and criterion (thesis Fig. 5.15)")
    bar("wrongly_occupied.png", lambda r: r["wrongly_occupied"], "voxels (mean ± sd)",
        "Wrongly occupied voxels in the room (floor layer excluded)")
    bar("band_wrongly_free.png", lambda r: r["band_wrongly_free"], "voxels (mean ± sd)",
        "Wrongly free voxels in the closet band (closet and 0.5 m in front)")
    bar("known.png", lambda r: r["known"] * 100, "reachable free floor known, % (mean ± sd)", "Floor explored")
    bar("collisions.png", lambda r: r["collided"], "runs with a collision (of 10)",
        "Runs in which the robot's cylinder met the true scene", count=True)
    bar("completed.png", lambda r: r["completed"], "runs completed (of 10)",
        "Runs that ended on their own with ≥ 95 % of the floor known", count=True)
    coverage_chart(rep, os.path.join(out, "arm_coverage.png"), plt)
    written.append("arm_coverage.png")
    return written


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("results")
    ap.add_argument("--charts", help="folder for the PNG charts (none without it)")
    ap.add_argument("--policies", default="thesis")
    ap.add_argument("--floor", default="removed")
    ap.add_argument("--gain", default="unknown")
    ap.add_argument("--resamples", type=int, default=10000)
    ap.add_argument("--seed", type=int, default=16)
    a = ap.parse_args()
    rows = load(a.results, a.policies, a.floor, a.gain)
    if not rows:
        sys.exit(f"{a.results}: no runs with policies {a.policies}, floor {a.floor}, gain {a.gain}")
    rep = Report(rows, a.resamples, a.seed)
    print(f"Condition: policies {a.policies}, floor {a.floor} (mobile), gain over {a.gain} voxels; "
          f"bootstrap: {a.resamples} resamples, seed {a.seed}, percentile intervals.")
    print()
    print("### Targets")
    print()
    print("\n".join(targets(rep)))
    print()
    print("### Configurations (mean ± sd over the seeds)")
    print()
    print("\n".join(summary_table(rep)))
    collisions = collision_table(rep)
    if collisions:
        print()
        print("### Where the collisions lie (scene objects the robot's cylinder met)")
        print()
        print("\n".join(collisions))
    print()
    print("### Comparisons behind the verdicts (difference of means a − b, 95 % bootstrap CI)")
    print()
    print("| claim | comparison | a − b | 95 % CI |")
    print("|---|---|---|---|")
    for claim, what, ca, cb, metric, digits in comparisons():
        res = rep.compare(ca, cb, metric)
        if res is None:
            continue
        v, ci = fmt_ci(res, digits)
        print(f"| {claim or '–'} | {what} | {v} | {ci} |")
    shares = occupied_share_table(rep)
    if shares:
        print()
        print("### Arm: the share of the voxels classified occupied that are wrong (claim 7)")
        print()
        print("Per run: wrongly occupied / (wrongly occupied + visible surface voxels classified occupied); the "
              "latter are the coverage times the object's visible surface voxels (part "
              f"{SURFACE_VOXELS['part']}, bottle {SURFACE_VOXELS['bottle']}). The object's voxels off its visible "
              "surface (inside it, or the underside on the table) classified occupied are not in the rows and not "
              "counted, so the share over all the voxels classified occupied is at most this. Mean ± sd over the runs; 95 % bootstrap interval of the mean, and of the "
              "difference of means.")
        print()
        print("\n".join(shares))
    if (a.policies, a.floor, a.gain) == ("thesis", "removed", "unknown"):
        seconds = second_conditions(rep, a.results, a.policies, a.floor, a.gain)
        if seconds:
            print()
            print("### The second conditions against this one (same configuration, one option changed; "
                  "difference of means, 95 % bootstrap CI)")
            print()
            print("\n".join(seconds))
    if a.charts:
        names = charts(rep, a.charts)
        print()
        print("Charts: " + ", ".join(names))
    if rep.missing:
        print()
        print("Not in the file (left out): " + "; ".join(sorted("/".join(c) for c in rep.missing)))


if __name__ == "__main__":
    main()
