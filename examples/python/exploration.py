"""An exploration loop driven from Python: the mobile planner decides, a Python function senses.

The sensor callback here asks the simulator, but it could command a real robot: it gets the body
pose (4x4) and returns the beams measured there as (origins, ends, hits) in world coordinates.

    PYTHONPATH=build/python python3 examples/python/exploration.py [--steps N] [--seed S]
"""

import argparse

import numpy as np

import intervox as iv

parser = argparse.ArgumentParser(description="The mobile base explores the lab room, sensing from Python.")
parser.add_argument("--steps", type=int, default=5, help="views planned after the look-around (default 5)")
parser.add_argument("--seed", type=int, default=1, help="noise seed (default 1)")
args = parser.parse_args()  # exits with 2 on a bad command line
if args.steps < 0 or args.seed < 0:
    parser.error("--steps and --seed must be >= 0")
lab = iv.make_lab_room(closet_material=iv.Material.specular())
rig = iv.SensorRig.mobile_base()
scans = 0


def sense(body):
    """The sensor source: one scan of every camera with the base at `body`."""
    global scans
    scans += 1
    return iv.simulate_rig(rig, lab.scene, body, seed=1000 * args.seed + scans)


params = iv.MobilePlannerParams()
params.max_steps = args.steps
params.region = lab.interior
planner = iv.MobilePlanner(rig, params)
grid = iv.IntervalGrid(0.05)
start = np.eye(4)
start[:3, 3] = lab.start

episode = iv.Episode(grid, planner, sense, start)
while episode.termination == iv.Termination.RUNNING:
    step = episode.step()
    plan = step.plan
    print(f"step {step.step}: {plan.reason.name.lower():8s} {plan.termination.name.lower():8s} "
          f"scans {len(plan.scans)} path {plan.path_length:5.2f} m gain {plan.gain:8.1f} "
          f"observed {grid.observed_count()}")
print(f"ended: {episode.termination.name.lower()} after {episode.distance_driven():.1f} m and {scans} scans")
