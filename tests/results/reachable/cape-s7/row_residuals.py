#!/usr/bin/env python3
"""RMS distance (m) from its target of each grid row of a position keyframe's particles, at the keyframe's frame.

Usage: row_residuals.py SCENE.json TRAJECTORY.csv OUT.csv
TRAJECTORY.csv: `keyframe export RUN_DIR --format csv` (frame,seconds,particle,x,y,z,...)."""
import csv, json, math, sys

if len(sys.argv) != 4:
    raise SystemExit(__doc__)
scene = json.load(open(sys.argv[1]))
nx = scene["cloth"]["nx"]
key = next(o for o in scene["objectives"] if o["type"] == "position")
targets = dict(zip(key["particles"], key["targets"]))
at = {int(r["particle"]): [float(r[k]) for k in "xyz"]
      for r in csv.DictReader(open(sys.argv[2])) if int(r["frame"]) == key["frame"]}
rows = {}
for p, t in targets.items():
    rows.setdefault(p // nx, []).append(math.dist(at[p], t) ** 2)
with open(sys.argv[3], "w", newline="") as out:
    w = csv.writer(out)
    w.writerow(["row", "particles", "rms_m", "worst_m"])
    for j in sorted(rows):
        w.writerow([j, len(rows[j]), "%.4f" % math.sqrt(sum(rows[j]) / len(rows[j])), "%.4f" % math.sqrt(max(rows[j]))])
