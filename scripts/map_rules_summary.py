#!/usr/bin/env python3
"""Summarises map_rules runs over many seeds, with intervals (docs/planning.md, "Open lying
groups", "Over 40 seeds").

map_rules (examples/experiments/map_rules.cpp) prints one row per run; runs of one configuration
may come from several invocations (--seeds N --first-seed S). Give each configuration a label and
its output files; the script pools the rows of each planner in them and prints, per label and
planner: runs, runs with a collision and the exact (Clopper-Pearson) 95 % interval of the rate,
the objects met, steps (mean ± sd and the 95 % percentile bootstrap interval of the mean), floor
known, the runs that ended with less of the floor known than --known-below (90 %) and the runs
that ended before the budget. With --ratio A B it also prints the ratio of A's
mean steps to B's with its bootstrap interval (groups resampled independently, seeded).

    scripts/map_rules_summary.py "mirror, open groups=out/m_1_10.txt,out/m_11_40.txt" \
        "diffuse, library=out/d_lib.txt" "diffuse, open groups=out/d_eh.txt" \
        [--planner "explained hazards"] [--ratio "diffuse, open groups" "diffuse, library"]

A seed that appears twice for one label and planner is an error (two runs of one seed pooled
twice would narrow the intervals). Needs numpy."""
import argparse
import pathlib
import re
import sys

import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from bootstrap import bootstrap, bootstrap_mean, clopper_pearson, mean_sd  # noqa: E402

# planner, seed, termination (may hold spaces), steps, known %, metres, [annex %], objects met
ROW = re.compile(r"^(?P<planner>thesis rules|library|explained hazards|explained)\s+(?P<seed>\d+)\s+"
                 r"(?P<term>[A-Za-z][A-Za-z ]*?)\s+(?P<steps>\d+)\s+(?P<known>[\d.]+)\s+(?P<dist>[\d.]+)\s+"
                 r"(?:(?P<annex>\d+)\s+)?(?P<met>-|(?:\S+:\d+ ?)+)(?:\s+\(mirrors told: \d+\))?\s*$")


def parse(text):
    """The run rows of a map_rules output: dicts of planner, seed, termination, steps, known,
    distance, annex (or None) and met ({object: poses})."""
    rows = []
    for line in text.splitlines():
        m = ROW.match(line)
        if not m:
            continue
        met = {}
        if m["met"] != "-":
            for item in m["met"].split():
                name, n = item.rsplit(":", 1)
                met[name] = int(n)
        rows.append({"planner": m["planner"], "seed": int(m["seed"]), "termination": m["term"].strip(),
                     "steps": int(m["steps"]), "known": float(m["known"]), "distance": float(m["dist"]),
                     "annex": float(m["annex"]) if m["annex"] is not None else None, "met": met})
    return rows


def pooled(groups, planner_filter):
    """{(label, planner): rows} over each label's files. Raises ValueError on a seed twice."""
    out = {}
    for label, files in groups:
        for f in files:
            for r in parse(pathlib.Path(f).read_text(encoding="utf-8")):
                if planner_filter and r["planner"] != planner_filter:
                    continue
                rows = out.setdefault((label, r["planner"]), [])
                if any(o["seed"] == r["seed"] for o in rows):
                    raise ValueError(f"{label}: seed {r['seed']} of {r['planner']} appears twice")
                rows.append(r)
    return out


def summary_table(data, rng, resamples=10000, known_below=90.0):
    """The markdown table, one row per (label, planner); known_below: the floor known % under
    which a run counts in the "runs < known_below % known" column."""
    lines = ["| configuration | planner | runs | runs with a collision (95 % interval of the rate) | objects met (runs) | "
             f"steps (95 % interval of the mean) | floor known % | runs < {known_below:g} % known | ended before the budget |",
             "|---|---|---:|---|---|---|---:|---:|---:|"]
    for (label, planner), rows in data.items():
        n = len(rows)
        k = sum(1 for r in rows if r["met"])
        lo, hi = clopper_pearson(k, n)
        objects = {}
        for r in rows:
            for name in r["met"]:
                objects[name] = objects.get(name, 0) + 1
        met = ", ".join(f"{name} {c}" for name, c in sorted(objects.items())) or "–"
        steps = [r["steps"] for r in rows]
        ci = bootstrap_mean(steps, resamples, rng)
        ci_text = f" [{ci[1]:.1f}, {ci[2]:.1f}]" if ci else ""
        ended = sum(1 for r in rows if r["termination"] != "budget")
        low = sum(1 for r in rows if r["known"] < known_below)
        lines.append(f"| {label} | {planner} | {n} | {k} of {n} ({100 * lo:.1f}–{100 * hi:.1f} %) | {met} | "
                     f"{mean_sd(steps, 1)}{ci_text} | {mean_sd([r['known'] for r in rows], 1)} | {low} | {ended} |")
    return "\n".join(lines)


def ratio_of_means(a, b):
    mb = b.mean(axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(mb != 0, a.mean(axis=1) / mb, np.nan)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("groups", nargs="+", help='"label=file[,file...]": one configuration\'s map_rules outputs')
    parser.add_argument("--planner", help="only this planner's rows (e.g. \"explained hazards\")")
    parser.add_argument("--ratio", nargs=2, metavar=("A", "B"), help="mean steps of label A over label B, with its interval")
    parser.add_argument("--seed", type=int, default=1, help="the bootstrap's seed (1 by default)")
    parser.add_argument("--known-below", type=float, default=90.0,
                        help="floor known %% under which a run is counted as ended short (90 by default)")
    args = parser.parse_args(argv)
    groups = []
    for g in args.groups:
        label, sep, files = g.partition("=")
        if not sep or not label or not files:
            parser.error(f"a group is label=file[,file...], got {g!r}")
        groups.append((label, files.split(",")))
    rng = np.random.default_rng(args.seed)
    try:
        data = pooled(groups, args.planner)
    except (OSError, ValueError) as e:
        parser.error(str(e))
    if not data:
        parser.error("no run rows found")
    if not 0.0 <= args.known_below <= 100.0:
        parser.error(f"--known-below must lie in [0, 100], got {args.known_below}")
    print(summary_table(data, rng, known_below=args.known_below))
    if args.ratio:
        by_label = {}
        for (label, _), rows in data.items():
            by_label.setdefault(label, []).extend(r["steps"] for r in rows)
        for label in args.ratio:
            if label not in by_label:
                parser.error(f"--ratio: no label {label!r}")
        est = bootstrap(by_label[args.ratio[0]], by_label[args.ratio[1]], ratio_of_means, 10000, rng)
        if est is None:
            print(f"\nsteps ratio {args.ratio[0]} / {args.ratio[1]}: too few runs for an interval")
        else:
            print(f"\nsteps ratio {args.ratio[0]} / {args.ratio[1]}: {est[0]:.2f} (95 % bootstrap interval {est[1]:.2f}–{est[2]:.2f})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
