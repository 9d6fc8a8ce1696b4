"""A first map from Python: simulate a depth frame in the lab room, insert it, query, save.

    PYTHONPATH=build/python python3 examples/python/first_map.py
"""

import numpy as np

import intervox as iv

lab = iv.make_lab_room()
camera = iv.DepthCamera.o3d100()
pose = iv.look_at(lab.start + [0, 0, 0.5], (0.3, 4.0, 0.8))          # camera to world, 4x4
frame = iv.simulate(camera, lab.scene, pose, seed=1)                 # frame.depth: (48, 64) float32

grid = iv.IntervalGrid(0.05)                                         # interval-mean, sparse
stats = grid.insert_depth_image(frame.depth, frame.intrinsics, frame.pose, max_range=frame.max_range)
print(stats)

voxels = grid.observed_voxels()                                      # dict of arrays
width = voxels["interval"][:, 1] - voxels["interval"][:, 0]
print(f"{len(width)} voxels observed, {grid.counts().occupied} occupied, mean interval width {width.mean():.3f}")
print("probability along the view:", grid.probability(np.linspace(pose[:3, 3], (0.3, 4.0, 0.8), 5)).round(3))
grid.save("first_map.ivx")
