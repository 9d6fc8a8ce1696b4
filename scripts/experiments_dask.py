#!/usr/bin/python3
"""Runs the experiments program in shards on a Dask cluster, then merges the shards.

    /usr/bin/python3 scripts/experiments_dask.py --program build/examples/experiments/experiments \\
        --shards 8 --out out/experiments [--scheduler tcp://HOST:8786] [--local-workers N] \\
        [--workers-per-shard 1] -- [experiments options: --seeds 10 --surfaces specular ...]

Each shard K of N runs `experiments OPTIONS --shard K/N --out OUT/shard-K --resume` (run i of
the sweep belongs to shard (i mod N) + 1), so a shard that is started again continues where it
stopped. When every shard has finished, `experiments --tables-from OUT/shard-*/results.csv --out
OUT` writes the merged results.csv, results.json and tables.md (row for row the same as one
process, apart from the timing columns).

Without --scheduler a LocalCluster of --local-workers processes (default: the CPU count) runs on
this machine. With --scheduler the shards run on that cluster's workers: the program and OUT must
then be reachable under the same paths on every worker (a shared file system), and the program
must have been built for the workers' machines.

Needs Debian's python3-distributed. Exit code 0 if every shard succeeded and the merge was
written; 1 if a shard failed (the finished shards are still merged); 2 for bad arguments.
"""
import argparse
import os
import pathlib
import subprocess
import sys


def run_shard(program, options, index, count, out, workers):
    """Runs one shard; returns (index, exit code, the tail of its output)."""
    cmd = [program, *options, "--shard", f"{index}/{count}", "--out", out, "--resume", "--quiet",
           "--workers", str(workers)]
    p = subprocess.run(cmd, capture_output=True, text=True)
    return index, p.returncode, (p.stdout + p.stderr)[-4000:]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--program", required=True, help="the experiments executable")
    ap.add_argument("--shards", type=int, required=True, help="number of shards N (>= 1)")
    ap.add_argument("--out", required=True, help="output folder (shards in OUT/shard-K)")
    ap.add_argument("--scheduler", help="address of a running Dask scheduler (default: a LocalCluster)")
    ap.add_argument("--local-workers", type=int, default=os.cpu_count() or 1, help="LocalCluster worker processes")
    ap.add_argument("--workers-per-shard", type=int, default=1, help="runs in parallel inside each shard")
    ap.add_argument("options", nargs=argparse.REMAINDER, help="-- then the experiments options")
    a = ap.parse_args()
    options = a.options[1:] if a.options[:1] == ["--"] else a.options
    if a.shards < 1 or a.local_workers < 1 or a.workers_per_shard < 1:
        ap.error("--shards, --local-workers and --workers-per-shard must be >= 1")
    for bad in ("--shard", "--out", "--tables-from", "--resume"):
        if bad in options:
            ap.error(f"{bad} is set by the driver; do not pass it after --")
    program = str(pathlib.Path(a.program).resolve())
    if not os.access(program, os.X_OK):
        ap.error(f"--program: {a.program} is not an executable file")
    try:
        from dask.distributed import Client, LocalCluster
    except ImportError:
        print("experiments_dask: needs Dask (Debian package python3-distributed)", file=sys.stderr)
        return 2
    out = pathlib.Path(a.out).resolve()
    out.mkdir(parents=True, exist_ok=True)
    shard_dirs = [str(out / f"shard-{k}") for k in range(1, a.shards + 1)]

    cluster = None
    if a.scheduler:
        client = Client(a.scheduler)
    else:
        cluster = LocalCluster(n_workers=min(a.local_workers, a.shards), threads_per_worker=1, processes=True,
                               dashboard_address=None)
        client = Client(cluster)
    try:
        futures = [client.submit(run_shard, program, options, k, a.shards, shard_dirs[k - 1], a.workers_per_shard,
                                 pure=False, key=f"experiments-shard-{k}-of-{a.shards}")
                   for k in range(1, a.shards + 1)]
        failed = []
        for future in futures:
            index, code, tail = future.result()
            status = "ok" if code == 0 else f"FAILED (exit code {code})"
            print(f"experiments_dask: shard {index}/{a.shards} {status}", flush=True)
            if code != 0:
                failed.append(index)
                print(tail, file=sys.stderr)
    finally:
        client.close()
        if cluster is not None:
            cluster.close()

    csvs = [str(pathlib.Path(d) / "results.csv") for d in shard_dirs if (pathlib.Path(d) / "results.csv").exists()]
    if not csvs:
        print("experiments_dask: no shard wrote results", file=sys.stderr)
        return 1
    merge = subprocess.run([program, "--tables-from", *csvs, "--out", str(out)], text=True)
    if merge.returncode != 0:
        return 1
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
