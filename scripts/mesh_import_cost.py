#!/usr/bin/env python3
"""What isolating assimp costs: `keyframe inspect FILE` on the character files, timed with a build that
imports in process (BEFORE, e.g. main before the isolation) and one that imports in a forked child (AFTER),
runs alternated; writes file,build,runs,median_s,min_s (CSV) to OUT.

  scripts/mesh_import_cost.py BEFORE_BINARY AFTER_BINARY OUT.csv [runs]"""
import csv, os, statistics, subprocess, sys, time

FILES = ["assets/character/BCN_Epileptic.X", "/usr/share/assimp/models/X/Testwuson.X"]

if len(sys.argv) < 4:
    print(__doc__)
    sys.exit(2)
before, after, out = sys.argv[1:4]
runs = int(sys.argv[4]) if len(sys.argv) > 4 else 21
root = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
rows = []
for f in FILES:
    path = f if os.path.isabs(f) else os.path.join(root, f)
    times = {"in_process": [], "isolated": []}
    for _ in range(runs):
        for build, binary in (("in_process", before), ("isolated", after)):
            t = time.perf_counter()
            subprocess.run([binary, "inspect", "--json", path], check=True, stdout=subprocess.DEVNULL)
            times[build].append(time.perf_counter() - t)
    for build, ts in times.items():
        rows.append({"file": f, "build": build, "runs": runs, "median_s": f"{statistics.median(ts):.4f}",
                     "min_s": f"{min(ts):.4f}"})
with open(out, "w", newline="") as fh:
    w = csv.DictWriter(fh, fieldnames=list(rows[0]))
    w.writeheader()
    w.writerows(rows)
