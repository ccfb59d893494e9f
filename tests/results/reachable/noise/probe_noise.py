#!/usr/bin/env python3
"""The diagnosis probe's "objective at the start" spread (phi's relative spread under control perturbations of
1e-9, report.json's sensitivity) for each drop-collider scene, on main (ordered-a) and on this branch
(noise/a, noise/b), and whether the scene has friction.

Usage: python3 tests/results/reachable/noise/probe_noise.py > tests/results/reachable/noise/probe_noise.csv"""
import json, os

R = "tests/results/reachable"


def noise(path):
    if not os.path.exists(path):
        return ""
    s = json.load(open(path)).get("sensitivity", {})
    v = s.get("objective_relative_noise_start")
    return "" if v is None else "%.3g" % v


print("scene,friction,relative_noise_before,relative_noise_after")
for i in range(12):
    name = "drop-collider-%d" % i
    scene = json.load(open(f"{R}/scenes/{name}.json"))
    friction = any(c.get("friction", 0) > 0 for c in scene["cloth"].get("colliders", []))
    after = noise(f"{R}/noise/a/reports/{name}.json") or noise(f"{R}/noise/b/reports/{name}.json")
    print(",".join([name, "yes" if friction else "no", noise(f"{R}/ordered-a/reports/{name}.json"), after]))
