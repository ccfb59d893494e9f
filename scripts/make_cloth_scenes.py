#!/usr/bin/env python3
"""Writes the cloth figure scene whose keyframes list one target per particle: shapes.json (the ring toss,
scenes/ring-toss.json, is written by scripts/make_ring_toss.py).

Run from the repository root: python3 scripts/make_cloth_scenes.py
"""
import json
import math


def dump(path, scene):
    if path.startswith("scenes/"):  # editors validate against the schema beside the scenes
        scene = {"$schema": "scene.schema.json", **scene}
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
