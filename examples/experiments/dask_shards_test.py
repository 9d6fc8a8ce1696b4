#!/usr/bin/python3
"""CTest: a tiny sweep run in shards on a Dask LocalCluster and merged gives the same results.csv
as one process, row for row (apart from the timing columns). Exit 77 (skipped) without Dask.

    dask_shards_test.py EXPERIMENTS_PROGRAM DRIVER_SCRIPT WORK_DIR
"""
import csv
import shutil
import subprocess
import sys
from pathlib import Path

try:
    import dask.distributed  # noqa: F401
except ImportError:
    print("skipped: Dask (python3-distributed) is not installed")
    sys.exit(77)

program, driver, work = sys.argv[1], sys.argv[2], Path(sys.argv[3])
shutil.rmtree(work, ignore_errors=True)
work.mkdir(parents=True)
tiny = ["--surfaces", "diffuse", "specular", "--updates", "bayes", "interval-mean", "--utilities", "max-entropy",
        "--no-arm", "--seeds", "2", "--resolution", "0.2", "--max-steps", "2", "--gain-stride", "8", "--no-figures"]
single = subprocess.run([program, *tiny, "--out", str(work / "single"), "--quiet", "--workers", "1"])
assert single.returncode == 0, "the single-process sweep failed"
sharded = subprocess.run([sys.executable, driver, "--program", program, "--shards", "3", "--local-workers", "2",
                          "--out", str(work / "sharded"), "--", *tiny])
assert sharded.returncode == 0, "the sharded sweep failed"


def rows(path):
    with open(path, newline="") as f:
        return [{k: v for k, v in r.items() if not k.startswith("seconds_")} for r in csv.DictReader(f)]


a, b = rows(work / "single" / "results.csv"), rows(work / "sharded" / "results.csv")
assert len(a) == 8, f"expected 8 runs, got {len(a)}"
assert len(b) == len(a), f"{len(b)} merged rows against {len(a)}"
for i, (x, y) in enumerate(zip(a, b)):
    assert x == y, f"row {i + 1} differs:\n{x}\n{y}"
print(f"ok: {len(a)} runs, sharded and merged equal to one process")
shutil.rmtree(work, ignore_errors=True)
