#!/usr/bin/env python3
"""A folded napkin's layers from a run's `keyframe export RUN --format csv`: over every frame, the pairs of a
particle (i, j) and its mirror (i, ny-1-j) across the fold that lie within 4 cm of each other across (x, z),
the least height between such a pair, and the lowest particle of the run.
Usage: fold_layers.py SCENE.json RUN/export/trajectory.csv"""
import csv
import json
import math
import sys

cloth = json.load(open(sys.argv[1]))["cloth"]
nx, ny = cloth["nx"], cloth["ny"]
at = {}
for r in csv.DictReader(open(sys.argv[2])):
    at[(int(r["frame"]), int(r["particle"]))] = (float(r["x"]), float(r["y"]), float(r["z"]))
pairs, least, lowest = 0, math.inf, math.inf
for f in sorted({f for f, _ in at}):
    lowest = min(lowest, min(at[(f, p)][1] for p in range(nx * ny)))
    for j in range(ny // 2):
        for i in range(nx):
            a, b = at[(f, j * nx + i)], at[(f, (ny - 1 - j) * nx + i)]
            if math.hypot(a[0] - b[0], a[2] - b[2]) < 0.04:
                pairs += 1
                least = min(least, abs(a[1] - b[1]))
print(f"mirror_pairs_within_4cm,{pairs}\nleast_height_between_pair_m,{least:.4f}\nlowest_particle_m,{lowest:.4f}")
