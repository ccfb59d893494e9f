#!/usr/bin/env python3
"""Writes the four cloth scenes the optimisation strategies were measured on
(tests/results/robustness/strategy_scenes/*.json), written the way a new user writes them: defaults
everywhere except the geometry, and keyframes that ask for a visible change of the uncontrolled motion.

Each scene is first simulated without controls (`keyframe simulate`), and its keyframe targets are that
motion's state at the keyframe plus the offset stated below, so every target is a modest change of a
motion the sheet really makes.

Run from the repository root after building: python3 scripts/make_strategy_scenes.py [path/to/keyframe]
"""
import json
import os
import struct
import subprocess
import sys
import tempfile

OUT = "tests/results/robustness/strategy_scenes"


def read_frame(path, frame):
    """Positions (list of (x, y, z)) of one frame of a trajectory.bin."""
    with open(path, "rb") as f:
        head = f.read(24)
        p, nframes = struct.unpack("<II", head[8:16])
        f.seek(24 + frame * p * 6 * 8)
        x = struct.unpack("<%dd" % (3 * p), f.read(3 * p * 8))
    return [x[3 * i:3 * i + 3] for i in range(p)]


def mean(points):
    return [sum(p[c] for p in points) / len(points) for c in range(3)]


def add(a, b):
    return [round(x + y, 4) for x, y in zip(a, b)]


def sheet_drop_on_sphere():
    """A 20x20, 1.2 m, 0.4 kg sheet dropped centred onto a sphere above the ground; centre-of-mass and
    one-corner keyframes at frame 30 (the corner lifted 15 cm, the sheet 10 cm to one side)."""
    scene = {
        "time": {"fps": 30, "frames": 30},
        "cloth": {"nx": 20, "ny": 20, "width": 1.2, "height": 1.2, "mass": 0.4, "origin": [-0.6, 0.9, -0.6],
                  "v_axis": [0, 0, 1],
                  "colliders": [{"type": "sphere", "center": [0, 0.5, 0], "radius": 0.3},
                                {"type": "ground", "center": [0, 0, 0], "axis": [0, 1, 0]}]},
        "controls": {"kind": "per_frame"},
    }
    keys = lambda x: [
        {"type": "center_of_mass", "frame": 30, "weight": 100, "target": add(mean(x), [0.1, 0, 0])},
        {"type": "position", "frame": 30, "weight": 100, "particles": [0], "targets": [add(x[0], [0, 0.15, 0])]}]
    return "sheet-on-sphere", scene, 30, keys


def flag_released_flat():
    """A 20x12 flag pinned at the two corners of one short edge, released flat in a vertical plane, no
    collider; its free bottom corner keyframed 20 cm out of the plane at frame 24."""
    scene = {
        "time": {"fps": 30, "frames": 24},
        "cloth": {"nx": 20, "ny": 12, "width": 1.0, "height": 0.6, "mass": 0.3, "origin": [0, 1.2, 0],
                  "pins": [0, 220]},
        "controls": {"kind": "per_frame"},
    }
    keys = lambda x: [{"type": "position", "frame": 24, "weight": 100, "particles": [19],
                       "targets": [add(x[19], [0, 0, 0.2])]}]
    return "flag-released-flat", scene, 24, keys


def towel_over_rail():
    """A 16x16 towel dropped over a horizontal capsule (a rail); its centre of mass 15 cm to one side at
    frame 40."""
    scene = {
        "time": {"fps": 30, "frames": 40},
        "cloth": {"nx": 16, "ny": 16, "width": 0.8, "height": 0.8, "mass": 0.3, "origin": [-0.4, 1.1, -0.4],
                  "v_axis": [0, 0, 1],
                  "colliders": [{"type": "capsule", "a": [0, 1.0, -0.7], "b": [0, 1.0, 0.7], "radius": 0.03},
                                {"type": "ground", "center": [0, 0, 0], "axis": [0, 1, 0]}]},
        "controls": {"kind": "per_frame"},
    }
    keys = lambda x: [{"type": "center_of_mass", "frame": 40, "weight": 100, "target": add(mean(x), [0.15, 0, 0])}]
    return "towel-over-rail", scene, 40, keys


def sheet_thrown_over_sphere():
    """A 16x16 sheet thrown over a sphere to land on a spot 30 cm beyond where the scene's throw lands;
    its initial velocities (one per particle) are the controls."""
    scene = {
        "time": {"fps": 30, "frames": 40},
        "cloth": {"nx": 16, "ny": 16, "width": 0.6, "height": 0.6, "mass": 0.2, "origin": [-1.5, 1.0, -0.3],
                  "v_axis": [0, 0, 1], "velocity": [3.0, 2.0, 0.0],
                  "colliders": [{"type": "sphere", "center": [0, 0.5, 0], "radius": 0.3},
                                {"type": "ground", "center": [0, 0, 0], "axis": [0, 1, 0]}]},
        "controls": {"kind": "initial_velocity"},
    }
    keys = lambda x: [{"type": "center_of_mass", "frame": 40, "weight": 100, "target": add(mean(x), [0.3, 0, 0])}]
    return "sheet-thrown-over-sphere", scene, 40, keys


def main():
    keyframe = sys.argv[1] if len(sys.argv) > 1 else "build/release/keyframe"
    os.makedirs(OUT, exist_ok=True)
    for make in (sheet_drop_on_sphere, flag_released_flat, towel_over_rail, sheet_thrown_over_sphere):
        name, scene, frame, keys = make()
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, name + ".json")
            with open(path, "w") as f:
                json.dump(scene, f)
            subprocess.run([keyframe, "simulate", path, "--out", os.path.join(tmp, "run")], check=True,
                           stdout=subprocess.DEVNULL)
            x = read_frame(os.path.join(tmp, "run", "trajectory.bin"), frame)
        scene["objectives"] = keys(x)
        with open(os.path.join(OUT, name + ".json"), "w") as f:
            json.dump(scene, f, indent=1)
            f.write("\n")
        print(name, json.dumps(scene["objectives"]))


if __name__ == "__main__":
    main()
