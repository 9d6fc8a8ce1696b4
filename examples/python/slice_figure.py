"""A matplotlib figure of a map slice coloured by interval width (blue narrow, red broad).

    PYTHONPATH=build/python python3 examples/python/slice_figure.py [--out slice.png]

Needs matplotlib (Debian: python3-matplotlib); without it the slice is written as a plain PNG.
"""

import argparse
import math

import numpy as np

import intervox as iv


def base_pose(position, yaw):
    """Body pose of the mobile base: at `position` on the floor, turned by `yaw` about z."""
    c, s = math.cos(yaw), math.sin(yaw)
    pose = np.eye(4)
    pose[:3, :3] = [[c, -s, 0], [s, c, 0], [0, 0, 1]]
    pose[:3, 3] = position
    return pose


parser = argparse.ArgumentParser(description="A slice of a map coloured by interval width.")
parser.add_argument("--out", default="slice.png", help="the figure to write (default slice.png)")
args = parser.parse_args()

lab = iv.make_lab_room(closet_material=iv.Material.absorbing())
rig = iv.SensorRig.mobile_base()
grid = iv.IntervalGrid(0.05)
for k, yaw in enumerate((0.0, math.radians(22.5))):  # two scans, turning on the spot between them
    grid.insert_beams(*iv.simulate_rig(rig, lab.scene, base_pose(lab.start, yaw), seed=k), max_range=4.0)

z = int(grid.keys(np.array([[0.0, 0.0, 0.5]]))[0, 2])  # the layer at the cameras' height
window = [[0, 0, z], [159, 119, z]]                     # the room's 8 x 6 m in 5 cm voxels
image = grid.render_slice(color=iv.ColorBy.INTERVAL_WIDTH, z=z, window=window)
out = args.out
try:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
except (ImportError, RuntimeError) as e:  # a broken matplotlib raises RuntimeError on import
    print("no matplotlib (%s): writing the bare slice" % e)
    iv.write_png(out, image)
else:
    fig, ax = plt.subplots(figsize=(8, 6))
    ax.imshow(image, extent=(0, 8, 0, 6))
    ax.set_title("interval width at z = 0.5 m (blue narrow, red broad, teal unobserved)")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    fig.savefig(out, dpi=100)
print("wrote", out)
