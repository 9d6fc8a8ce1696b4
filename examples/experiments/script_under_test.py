"""Loads the script a test is about, given as the test's first argument, as a module.

Shared by the Python tests of the experiment scripts (run as `python3 TEST.py SCRIPT`)."""
import importlib.util
import sys


def load(name):
    """The module of the script at sys.argv[1] (removed from argv, so unittest does not see it)."""
    path = sys.argv.pop(1) if len(sys.argv) > 1 else ""
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def write_csv(path, fields, rows):
    """Writes \\p rows (dicts) as a CSV file with the header \\p fields."""
    import csv
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fields)
        w.writeheader()
        w.writerows(rows)
