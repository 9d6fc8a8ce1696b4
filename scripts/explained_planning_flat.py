#!/usr/bin/env python3
"""The mobile planner with and without explained free space, as a new user tries it: an unbounded
grid, a flat that is not the lab room (the world of examples/explain_survey --world flat: two rooms
joined by a doorway, a wardrobe with a mirror front, a black sofa), the thesis' eight cameras or one
forward camera, the episode runner with the simulator as the sensor source. Prints, per run, how the
episode ended, its steps, the distance driven and the places along the driven path (every 5 cm) where the footprint meets a
true obstacle or lies outside the flat (driven through a wall) and the first thing met, then the
share of the reachable floor of each room whose column the grid knows free (at the end), then the
mean and standard deviation per planner (docs/planning.md, "Planning on explained free space"),
and whether the robot's centre got into the second room (x > 5.46 m: beyond the doorway's wall by
the robot radius) and how many passage views it took (--passage-views); --driven-paths turns on the
way back (params.driven_paths), --hazards the unexplained hazards (params.unexplained_hazards),
--open-group-hazards with them also the lying columns open to unexplored space
(params.open_group_hazards), --known-surfaces tells the explained planner the flat's floor plan
(walls: inner faces, the doorway left open) and/or the wardrobe's mirror front
(params.known_surfaces), --planners which planners run (both by default).

Usage (after the build): PYTHONPATH=build/python /usr/bin/python3 scripts/explained_planning_flat.py
    [--seeds 1 2 3] [--rig eight|one] [--update bayes|interval] [--steps 15] [--resolution 0.1]
    [--start-free-radius R] [--start-rule voxels|columns] [--face-along-path] [--passage-views] [--driven-paths]
    [--hazards [--open-group-hazards]] [--find-mirrors [--max-inconsistent-share S]] [--known-surfaces walls wardrobe]
    [--planners plain explained]
"""
import argparse
import math
import statistics
import sys

import numpy as np

import intervox as iv

ROBOT_RADIUS = 0.36          # MobilePlannerParams' default robot radius
BAND = (0.2, 0.8)            # the robot's height band above the floor (floor_clearance, obstacle_height)
INTERIOR = ((0.0, 0.0), (9.0, 4.0))
START = (0.8, 1.8)
PARTITION_X = 5.05           # the wall between the rooms (its centre)


def flat(mirror):
    """The flat and its obstacles as (name, (xmin, ymin, zmin), (xmax, ymax, zmax))."""
    wood = iv.Material.diffuse()
    boxes = [
        ("floor", (-0.1, -0.1, -0.1), (9.1, 4.1, 0.0)),
        ("wall_south", (-0.1, -0.1, 0.0), (9.1, 0.0, 2.6)),
        ("wall_north", (-0.1, 4.0, 0.0), (9.1, 4.1, 2.6)),
        ("wall_west", (-0.1, 0.0, 0.0), (0.0, 4.0, 2.6)),
        ("wall_east", (9.0, 0.0, 0.0), (9.1, 4.0, 2.6)),
        ("partition_south", (5.0, 0.0, 0.0), (5.1, 1.5, 2.6)),
        ("partition_north", (5.0, 2.4, 0.0), (5.1, 4.0, 2.6)),
        ("lintel", (5.0, 1.5, 2.1), (5.1, 2.4, 2.6)),
        ("wardrobe", (1.0, 3.4, 0.0), (2.5, 4.0, 2.0)),
        ("table", (6.5, 2.5, 0.7), (8.0, 3.5, 0.75)),
        ("cabinet", (8.3, 0.3, 0.0), (8.9, 1.0, 1.2)),
    ]
    scene = iv.Scene()
    for name, lo, hi in boxes:
        scene.add_box((lo, hi), wood, name)
    scene.add_quad((1.05, 3.399, 0.05), (1.4, 0.0, 0.0), (0.0, 0.0, 1.9),
                   iv.Material.mirror() if mirror else wood, "wardrobe_front")
    sofa = ("sofa", (2.8, 0.0, 0.0), (4.6, 0.9, 0.8))
    scene.add_box((sofa[1], sofa[2]), iv.Material.absorbing(), "sofa")
    obstacles = [b for b in boxes if b[0] not in ("floor", "lintel")] + [sofa]
    return scene, obstacles


def face(axis, value, lo, hi):
    """The face at value along axis (0 x, 1 y) of the box lo..hi (x, y, z), as an iv.PlanePatch."""
    normal = [0.0, 0.0, 0.0]
    normal[axis] = 1.0
    center = [(a + b) / 2 for a, b in zip(lo, hi)]
    center[axis] = value
    other = 1 - axis  # the horizontal extent along the other axis, the vertical along z
    return iv.PlanePatch(center, normal, (hi[other] - lo[other]) / 2, (hi[2] - lo[2]) / 2)


def known_surfaces(names):
    """What a user of the flat knows: "walls", the inner faces of its outer walls and of the
    partition on both sides of the doorway (y 1.5-2.4 m below 2.1 m left open); "wardrobe", the
    mirror front (y 3.399 m, x 1.05-2.45 m, z 0.05-1.95 m)."""
    out = []
    if "walls" in names:
        (x0, y0), (x1, y1) = INTERIOR
        h = 2.6
        out += [face(0, x0, (x0, y0, 0), (x0, y1, h)), face(0, x1, (x1, y0, 0), (x1, y1, h)),
                face(1, y0, (x0, y0, 0), (x1, y0, h)), face(1, y1, (x0, y1, 0), (x1, y1, h))]
        for x in (5.0, 5.1):  # the partition's two faces around the doorway
            out += [face(0, x, (x, 0.0, 0), (x, 1.5, h)), face(0, x, (x, 2.4, 0), (x, 4.0, h)),
                    face(0, x, (x, 1.5, 2.1), (x, 2.4, h))]
    if "wardrobe" in names:
        out.append(face(1, 3.399, (1.05, 3.399, 0.05), (2.45, 3.399, 1.95)))
    return out


def rig_named(name):
    if name == "eight":
        return iv.SensorRig.mobile_base()
    rig = iv.SensorRig()
    mount = np.eye(4)  # optical frame (z forward, x right, y down) to the body frame, at the front, 0.5 m up
    mount[:3, :3] = np.array([[0, 0, 1], [-1, 0, 0], [0, -1, 0]])
    mount[:3, 3] = (0.3, 0.0, 0.5)
    rig.add(iv.DepthCamera.o3d100(), mount, "front")
    return rig


def collision(x, y, obstacles):
    """What the robot's disc at (x, y) meets: the first obstacle within its height band, "outside"
    if it lies outside the flat, or None."""
    (x0, y0), (x1, y1) = INTERIOR
    if not (x0 < x < x1 and y0 < y < y1):
        return "outside"
    for name, lo, hi in obstacles:
        if hi[2] < BAND[0] or lo[2] > BAND[1]:
            continue
        dx = max(lo[0] - x, 0.0, x - hi[0])
        dy = max(lo[1] - y, 0.0, y - hi[1])
        if math.hypot(dx, dy) < ROBOT_RADIUS:
            return name
    return None


def reachable_floor(obstacles, resolution):
    """The flat's floor the robot's centre can reach from the start: the centres of the
    resolution's cells (a 0.1 m grid's columns) where the disc meets nothing, joined to the start's
    cell by 4-neighbours. Returns the cells' centres (x, y) as an (N, 2) array."""
    nx, ny = round(INTERIOR[1][0] / resolution), round(INTERIOR[1][1] / resolution)
    ok = [[collision((i + 0.5) * resolution, (j + 0.5) * resolution, obstacles) is None for j in range(ny)]
          for i in range(nx)]
    start = (int(START[0] / resolution), int(START[1] / resolution))
    seen, todo = {start}, [start]
    while todo:
        i, j = todo.pop()
        for a, b in ((i + 1, j), (i - 1, j), (i, j + 1), (i, j - 1)):
            if 0 <= a < nx and 0 <= b < ny and ok[a][b] and (a, b) not in seen:
                seen.add((a, b))
                todo.append((a, b))
    return np.array([((i + 0.5) * resolution, (j + 0.5) * resolution) for i, j in sorted(seen)])


def floor_known(grid, cells, resolution):
    """The share of cells whose column the grid knows free: every voxel of the robot's band free
    (the library's column projection, project_columns)."""
    zs = np.arange(BAND[0] + resolution / 2, BAND[1], resolution)
    points = np.array([[(x, y, z) for z in zs] for x, y in cells])
    return float(np.mean(np.all(grid.occupancy(points) == 1, axis=1))) if len(cells) else 1.0


def run(explained, seed, args):
    scene, obstacles = flat(mirror=True)
    rig = rig_named(args.rig)
    params = iv.MobilePlannerParams()
    params.max_steps = args.steps
    params.threads = 1
    params.seed = seed
    params.explained = explained
    if args.start_free_radius is not None:
        params.start_free_radius = args.start_free_radius
    if args.start_rule == "columns":
        params.start_free_columns = True  # the thesis' rule (with --start-free-radius 1 its radius)
    params.face_along_path = args.face_along_path
    params.find_mirrors = args.find_mirrors
    params.unexplained_hazards = args.hazards
    params.open_group_hazards = args.open_group_hazards
    params.max_inconsistent_share = args.max_inconsistent_share
    params.passage_views = args.passage_views
    params.driven_paths = args.driven_paths
    if explained:
        params.known_surfaces = known_surfaces(args.known_surfaces)
    planner = iv.MobilePlanner(rig, params)
    grid = iv.BayesGrid(args.resolution) if args.update == "bayes" else iv.IntervalGrid(args.resolution)
    start = np.eye(4)
    start[:3, 3] = (START[0], START[1], 0.0)
    calls = [0]

    def source(body):
        calls[0] += 1
        return iv.simulate_rig(rig, scene, body, seed=seed * 1000 + calls[0])

    episode = iv.Episode(grid, planner, source, start)
    termination = episode.run()
    trajectory = episode.trajectory
    # Every 5 cm along the driven path (straight between consecutive trajectory poses), so that a
    # path of long segments (face-along-path) is checked as densely as one of short ones.
    places = [trajectory[0][:2, 3]]
    for a, b in zip(trajectory[:-1], trajectory[1:]):
        n = max(1, math.ceil(np.linalg.norm(b[:2, 3] - a[:2, 3]) / 0.05))
        places += [a[:2, 3] + (b[:2, 3] - a[:2, 3]) * (i / n) for i in range(1, n + 1)]
    met = [collision(p[0], p[1], obstacles) for p in places]
    first = next((m for m in met if m), "-")
    floor = reachable_floor(obstacles, args.resolution)
    rooms = [floor[floor[:, 0] < PARTITION_X], floor[floor[:, 0] > PARTITION_X]]
    return {"termination": str(termination).split(".")[-1], "steps": len(episode.steps) - 1,
            "distance": episode.distance_driven(), "poses": len(places),
            "collisions": sum(m is not None for m in met), "first": first,
            "known1": 100 * floor_known(grid, rooms[0], args.resolution),
            "known2": 100 * floor_known(grid, rooms[1], args.resolution),
            "room2": bool(any(p[0] > 5.1 + ROBOT_RADIUS for p in places)),
            "passage_views": sum(1 for st in episode.steps if st.plan.reason == iv.ViewReason.PASSAGE)}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, nargs="+", default=[1, 2, 3])
    parser.add_argument("--rig", choices=["eight", "one"], default="eight")
    parser.add_argument("--update", choices=["bayes", "interval"], default="bayes")
    parser.add_argument("--steps", type=int, default=15)
    parser.add_argument("--resolution", type=float, default=0.1)
    parser.add_argument("--start-free-radius", type=float, default=None,
                        help="m around the start taken as clear (default: the planner's, the rig's blind zone)")
    parser.add_argument("--start-rule", choices=["voxels", "columns"], default="voxels",
                        help="the library's start rule (default) or the thesis' whole columns")
    parser.add_argument("--face-along-path", action="store_true", help="turn on the spot, drive forward only")
    parser.add_argument("--find-mirrors", action="store_true",
                        help="the explained planner finds mirrors before every plan (params.find_mirrors)")
    parser.add_argument("--passage-views", action="store_true",
                        help="views that open passages such as a doorway seen by too few scans (params.passage_views)")
    parser.add_argument("--driven-paths", action="store_true",
                        help="the way back: cells of the paths the robot drove stay passable (params.driven_paths)")
    parser.add_argument("--max-inconsistent-share", type=float, default=1.0,
                        help="with --find-mirrors: the region analysis' opacity test (1: off)")
    parser.add_argument("--hazards", action="store_true",
                        help="the explained planner keeps off columns only lying beams made free "
                             "(params.unexplained_hazards)")
    parser.add_argument("--open-group-hazards", action="store_true",
                        help="with --hazards: the lying columns of groups open to unexplored space keep the robot "
                             "off too (params.open_group_hazards)")
    parser.add_argument("--known-surfaces", nargs="+", choices=["walls", "wardrobe"], default=[],
                        help="surfaces the explained planner is told (params.known_surfaces): the floor plan's "
                             "walls (the doorway left open) and/or the wardrobe's mirror front")
    parser.add_argument("--planners", nargs="+", choices=["plain", "explained"], default=["plain", "explained"],
                        help="which planners run (default: both)")
    args = parser.parse_args()
    print(f"flat (mirror-fronted wardrobe, black sofa, doorway), unbounded {args.update} grid at "
          f"{args.resolution} m, {args.rig} camera(s), {args.steps} steps at most"
          + (f", known surfaces: {' '.join(args.known_surfaces)}" if args.known_surfaces else "")
          + (", open group hazards" if args.open_group_hazards else ""))
    print("planner    seed  termination          steps  distance_m  places  places_in_collision  first_met  "
          "second_room  passage_views  floor_known_%_room1  room2")
    results = {}
    for name in ("plain", "explained"):
        if name not in args.planners:
            continue
        explained = name == "explained"
        for seed in args.seeds:
            r = run(explained, seed, args)
            results.setdefault(name, []).append(r)
            print(f"{name:10} {seed:4}  {r['termination']:20} {r['steps']:5}  {r['distance']:10.2f}  "
                  f"{r['poses']:6}  {r['collisions']:19}  {r['first']:9}  {'yes' if r['room2'] else 'no':11}  "
                  f"{r['passage_views']:13}  {r['known1']:19.1f}  {r['known2']:5.1f}")
    for name, rs in results.items():
        c = [r["collisions"] for r in rs]
        s = [r["steps"] for r in rs]
        k1 = [r["known1"] for r in rs]
        k2 = [r["known2"] for r in rs]
        sd = lambda v: statistics.stdev(v) if len(v) > 1 else 0.0
        print(f"{name}: runs with a collision {sum(x > 0 for x in c)} of {len(c)}; places in collision "
              f"{statistics.mean(c):.1f} ± {sd(c):.1f}; steps {statistics.mean(s):.1f} ± {sd(s):.1f}; "
              f"runs in the second room (x > 5.46 m) {sum(r['room2'] for r in rs)} of {len(rs)}; reachable floor "
              f"known: room 1 {statistics.mean(k1):.1f} ± {sd(k1):.1f} %, room 2 {statistics.mean(k2):.1f} ± {sd(k2):.1f} %")
    return 0


if __name__ == "__main__":
    sys.exit(main())
