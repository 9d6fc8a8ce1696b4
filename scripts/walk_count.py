#!/usr/bin/env python3
"""Count the files a reader enters when following one call of the library through the code.

A walk is what a reader does who follows a call from the user's code down every function it
calls, in the order they are called, reading each function once: scripts/walk_count/walk_driver.cpp,
built with -finstrument-functions, records every function entered and left while tracing is on;
this script keeps each function's *first* entry, in order (a depth-first reading of the dynamic call
tree, each function read once), maps it to the header that defines it (addr2line on the driver,
built -O0 -g so that nothing is inlined), keeps the library's headers (include/intervox/...), and
counts
  - files: the headers entered;
  - functions: the library functions read;
  - returns: the times the reading moves to a header it has already read (from a callee back to a
    caller's file to read its next callee counts: the reader goes back there).
Functions of the standard library and Eigen are not instrumented (left out).

Usage: walk_count.py [--list] DRIVER TRACE [DRIVER TRACE ...]
  prints one line per (DRIVER, TRACE) pair: files, functions, returns; --list also prints the files
  in the order first entered, with the number of functions read in each.
docs/notes/code-walks.md says how the driver is built and what the counts were.
"""
import subprocess
import sys


def first_entries(trace_path):
    seen, order = set(), []
    with open(trace_path) as f:
        for line in f:
            kind, addr = line.split()
            if kind == ">" and addr not in seen:
                seen.add(addr)
                order.append(addr)
    return order


def resolve(driver, addrs):
    out = subprocess.run(["addr2line", "-f", "-C", "-e", driver], input="\n".join(addrs) + "\n",
                         capture_output=True, text=True, check=True).stdout.splitlines()
    if len(out) != 2 * len(addrs):
        sys.exit(f"walk_count: addr2line answered {len(out)} lines for {len(addrs)} addresses")
    res = {}
    for i, a in enumerate(addrs):
        name, where = out[2 * i], out[2 * i + 1]
        path = where.rsplit(":", 1)[0]
        res[a] = (name, path)
    return res


def library_header(path):
    marker = "include/intervox/"
    i = path.find(marker)
    return path[i + len("include/"):] if i >= 0 else None


def walk(driver, trace):
    order = first_entries(trace)
    where = resolve(driver, order)
    seq = []
    for a in order:
        header = library_header(where[a][1])
        if header:
            seq.append((header, where[a][0]))
    visited, files, returns, prev = set(), [], 0, None
    per_file = {}
    for header, _ in seq:
        if header != prev and header in visited:
            returns += 1
        if header not in visited:
            visited.add(header)
            files.append(header)
        per_file[header] = per_file.get(header, 0) + 1
        prev = header
    return files, per_file, len(seq), returns


def main(argv):
    listing = "--list" in argv
    args = [a for a in argv if a != "--list"]
    if not args or len(args) % 2:
        sys.exit(__doc__)
    for driver, trace in zip(args[0::2], args[1::2]):
        files, per_file, functions, returns = walk(driver, trace)
        print(f"{trace}: {len(files)} files, {functions} functions, {returns} returns to a file already read")
        if listing:
            for h in files:
                print(f"  {h} ({per_file[h]} functions)")


if __name__ == "__main__":
    main(sys.argv[1:])
