#!/usr/bin/env python3
"""Writes the cloth figure scenes whose keyframes list one target per particle (shapes, ring toss).

Run from the repository root: python3 scripts/make_cloth_scenes.py
"""
import json
import math


def dump(path, scene):
    with open(path, "w") as f:
        json.dump(scene, f, indent=1)
        f.write("\n")


def r4(v):
    return [round(c, 4) for c in v]


# Shapes (paper fig. 4): a 16x16 sheet hanging from its top edge is swung forward until it sticks out
# horizontally (frame 20), then back into a scoop curving the other way (frame 45).
n, size = 16, 1.0
d = size / (n - 1)
top = 1.5
flat, scoop = [], []
R = 0.45
for j in range(n):
    for i in range(n):
        x = -0.5 + i * d
        s = (n - 1 - j) * d  # arc length down from the pinned top edge
        flat.append(r4([x, top, s]))
        th = s / R
        scoop.append(r4([x, top - R * math.sin(th), -(R - R * math.cos(th))]))
dump("scenes/shapes.json", {
    "seed": 1,
    "time": {"fps": 30, "substeps": 4, "frames": 45},
    "cloth": {"nx": n, "ny": n, "width": size, "height": size, "origin": [-0.5, top - size, 0],
              "u_axis": [1, 0, 0], "v_axis": [0, 1, 0], "mass": 0.3, "pins": "top_edge",
              "cg_tolerance": 1e-6},
    "objectives": [
        {"type": "position", "frame": 20, "weight": 100, "targets": flat},
        {"type": "position", "frame": 45, "weight": 100, "targets": scoop},
    ],
    "controls": {"kind": "per_frame", "alpha": 1e-5},
    "optimizer": {"max_evaluations": 60, "ftol_rel": 1e-9},
    "render": {"camera": {"eye": [2.6, 2.0, 2.6], "target": [0, 1.0, 0]}},
})

# Ring toss (paper fig. 5): a 50x50 sheet thrown through a ring whose axis is the direction of the throw,
# spinning a half turn about that axis on the way (the corners trade sides by frame 24).
n, size = 50, 0.4
cx0, cy0 = -1.2, 1.0
com_frame, flip_frame = 15, 24
t = flip_frame / 30.0
vx, vy = 2.4, 2.85
cx1, cy1 = cx0 + vx * t, cy0 + vy * t - 0.5 * 9.81 * t * t
h = size / 2
corners = [0, n - 1, (n - 1) * n, n * n - 1]
# corner (i, j) sits at (-h + i d, 0, -h + j d) from the centre; half a turn about x flips z.
flip = [r4([cx1 + (-h if c % n == 0 else h), cy1, (h if c // n == 0 else -h)]) for c in corners]
dump("scenes/ring-toss.json", {
    "seed": 1,
    "time": {"fps": 30, "substeps": 1, "frames": flip_frame},
    "cloth": {"nx": n, "ny": n, "width": size, "height": size, "origin": [cx0 - h, cy0, -h],
              "u_axis": [1, 0, 0], "v_axis": [0, 0, 1], "mass": 0.2, "velocity": [vx, vy, 0],
              "cg_tolerance": 1e-6,
              "colliders": [{"type": "torus", "center": [0, 1.2, 0], "axis": [1, 0, 0], "radius": 0.3,
                             "tube_radius": 0.03, "thickness": 0.01, "stiffness": 1e3}]},
    "objectives": [
        {"type": "center_of_mass", "frame": com_frame, "weight": 100, "target": [0, 1.2, 0]},
        {"type": "position", "frame": flip_frame, "weight": 10, "particles": corners, "targets": flip},
    ],
    "controls": {"kind": "initial_velocity", "alpha": 1e-3},
    "optimizer": {"max_evaluations": 40, "ftol_rel": 1e-10},
    "render": {"camera": {"eye": [0.5, 2.2, 3.2], "target": [0, 1.0, 0]}},
})
