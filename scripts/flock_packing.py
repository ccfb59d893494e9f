#!/usr/bin/env python3
"""Per-frame packing of a flock run: speeds, neighbours within the matching radius and the explicit step's
overshoot h (matching.strength x summed neighbour weights + drag.strength) / mass, the quantity a flock step
refuses at 2 or more (FlockSystem::stable_velocity_update). The overshoot is taken at frames, not at every
step. Standard library only.

Usage: scripts/flock_packing.py RUN_DIR [EVERY]   (CSV on stdout; EVERY: frame stride, default 10)"""
import collections, json, math, os, struct, sys

if len(sys.argv) < 2:
    raise SystemExit(__doc__)
run = sys.argv[1]
every = int(sys.argv[2]) if len(sys.argv) > 2 else 10
scene = json.load(open(os.path.join(run, "scene.json")))
flock = scene["flock"]
c = flock.get("matching", {}).get("strength", 0.5)
R = flock.get("matching", {}).get("radius", 3.0)
drag = flock.get("drag", {}).get("strength", 0.2)
mass = flock.get("mass", 1.0)
time = scene["time"]
h = 1.0 / (time.get("fps", 30) * time.get("substeps", 1))

with open(os.path.join(run, "trajectory.bin"), "rb") as f:
    if f.read(8) != b"KFTRAJ01":
        raise SystemExit(f"{run}/trajectory.bin: not a keyframe trajectory")
    p, frames = struct.unpack("<II", f.read(8))
    f.read(8)
    state = 6 * p * 8
    print("frame,speed_max,speed_mean,neighbours_mean,neighbours_max,overshoot_max")
    for k in list(range(0, frames, every)) + ([frames - 1] if (frames - 1) % every else []):
        f.seek(24 + k * state)
        xv = struct.unpack(f"<{6 * p}d", f.read(state))
        x, z = xv[0:3 * p:3], xv[2:3 * p:3]
        vx, vz = xv[3 * p::3], xv[3 * p + 2::3]
        cells = collections.defaultdict(list)
        for i in range(p):
            cells[(math.floor(x[i] / R), math.floor(z[i] / R))].append(i)
        count, weight = [0] * p, [0.0] * p
        for (cx, cz), members in cells.items():
            near = [j for dx in (-1, 0, 1) for dz in (-1, 0, 1) for j in cells.get((cx + dx, cz + dz), ())]
            for i in members:
                xi, zi = x[i], z[i]
                for j in near:
                    r2 = (x[j] - xi) ** 2 + (z[j] - zi) ** 2
                    if j != i and r2 < R * R:
                        count[i] += 1
                        weight[i] += (1 - r2 / (R * R)) ** 3
        speeds = [math.hypot(a, b) for a, b in zip(vx, vz)]
        print(f"{k},{max(speeds):.6g},{sum(speeds) / p:.6g},{sum(count) / p:.6g},{max(count)},"
              f"{h * (c * max(weight) + drag) / mass:.6g}")
