#!/usr/bin/env python3
"""Joins the generated cloth scenes' conditioning (tests/opt/reachable_scenes_test.cpp,
ReachableScenes.DISABLED_ConditioningOfEveryClothScene) with their results: one row a scene (its worst keyframe's
displacement under a change of the variant by 1e-3 and 1e-4 of itself, in tolerances; pass; miss), and the pass
rate of the well-conditioned scenes (moved under one tolerance by 1e-3) against the knife edges.
Result files merge as in scripts/reachable_classes.py (a scene counts once, as the last file measured it).

Usage: scripts/reachable_conditioning.py OUT.csv CONDITIONING.csv IN.csv ..."""
import csv, sys

if len(sys.argv) < 4:
    raise SystemExit(__doc__)
result = {}
for f in sys.argv[3:]:
    for r in csv.DictReader(open(f)):
        result[r["scene"]] = r
moved = {}
for r in csv.DictReader(open(sys.argv[2])):
    moved.setdefault(r["scene"], {"class": r["class"]})[r["eps"]] = float(r["worst_displacement_tol"])
rows = []
for scene, m in moved.items():
    if scene not in result:
        raise SystemExit(f"{scene}: no result row in the files given")
    r = result[scene]
    rows.append([scene, m["class"], "%.3g" % m["0.001"], "%.3g" % m["0.0001"],
                 "yes" if m["0.001"] > 1 else "no", r["pass"], "%.3g" % float(r["miss_after"])])
with open(sys.argv[1], "w", newline="") as out:
    w = csv.writer(out)
    w.writerow(["scene", "class", "moved_1e-3", "moved_1e-4", "knife_edge", "pass", "miss_after"])
    w.writerows(rows)
for label, edge in (("well conditioned", "no"), ("knife edge", "yes")):
    rs = [r for r in rows if r[4] == edge]
    print(f"{label}: {sum(r[5] == 'yes' for r in rs)} of {len(rs)} pass"
          + "".join(f"; fails {r[0]} ({r[6]} tol)" for r in rs if r[5] != "yes"))
