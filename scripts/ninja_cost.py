#!/usr/bin/env python3
"""Where a build's time went, from Ninja's log (docs/performance.md, "Build and CI cost").

Usage: python3 scripts/ninja_cost.py BUILD_DIR [--top N]

Reads BUILD_DIR/.ninja_log (the last build of every output: Ninja keeps one line per output, the
newest last) and prints, per part of the project (tests, examples, Python, benchmarks, fuzz-corpus
replays, other), the sum of the step times (the CPU the build needs, one core per step) and the
span from the first step's start to the last step's end (its wall time), then the N longest steps.
Only the steps of the latest build are counted: Ninja restarts its clock at every run, so a step
whose start lies after the end of the log's last line began in an earlier run and is dropped.
"""
import argparse
import pathlib
import sys


def part_of(path: str) -> str:
    """The part of the project an output of the build belongs to."""
    if path.startswith("tests/") and "fuzz" in path:
        return "fuzz-corpus replays"
    for prefix, name in (("tests/", "tests"), ("examples/", "examples"), ("python/", "Python module"),
                         ("bench/", "benchmarks")):
        if path.startswith(prefix):
            return name
    return "other"


def read_log(log: pathlib.Path):
    """The steps of the latest build as (start_ms, end_ms, output); one per command (outputs of one
    command share its hash)."""
    lines = log.read_text().splitlines()
    if not lines or not lines[0].startswith("# ninja log v"):
        raise SystemExit(f"ninja_cost: {log} is not a Ninja log")
    rows = []
    for line in lines[1:]:
        fields = line.split("\t")
        if len(fields) != 5:
            raise SystemExit(f"ninja_cost: {log}: malformed line {line!r}")
        rows.append((int(fields[0]), int(fields[1]), fields[3], fields[4]))
    # Ninja appends; a new run restarts at 0 ms. Keep the rows after the last restart.
    first = 0
    for i in range(1, len(rows)):
        if rows[i][0] < rows[i - 1][0] and rows[i][1] < rows[i - 1][1] and rows[i][0] == 0:
            first = i
    seen = set()
    steps = []
    for start, end, output, command_hash in rows[first:]:
        if command_hash in seen:
            continue
        seen.add(command_hash)
        steps.append((start, end, output))
    return steps


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("build_dir", type=pathlib.Path)
    parser.add_argument("--top", type=int, default=15, help="how many of the longest steps to list")
    args = parser.parse_args()
    steps = read_log(args.build_dir / ".ninja_log")
    if not steps:
        print("ninja_cost: no steps in the log", file=sys.stderr)
        return 1
    parts = {}
    for start, end, output in steps:
        cpu, count = parts.get(part_of(output), (0, 0))
        parts[part_of(output)] = (cpu + end - start, count + 1)
    span = max(end for _, end, _ in steps) - min(start for start, _, _ in steps)
    total = sum(cpu for cpu, _ in parts.values())
    print(f"| part | steps | CPU (sum of step times) |\n|---|---:|---:|")
    for name, (cpu, count) in sorted(parts.items(), key=lambda item: -item[1][0]):
        print(f"| {name} | {count} | {cpu / 1000:.0f} s |")
    print(f"| **all** | {len(steps)} | **{total / 1000:.0f} s** in a span of {span / 1000:.0f} s |")
    print(f"\nlongest {args.top} steps:")
    for start, end, output in sorted(steps, key=lambda s: s[0] - s[1])[:args.top]:
        print(f"  {(end - start) / 1000:7.1f} s  {output}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
