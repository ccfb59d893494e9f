#!/usr/bin/env python3
"""Joins the generated cloth scenes' conditioning (tests/opt/reachable_scenes_test.cpp,
ReachableScenes.DISABLED_ConditioningOfEveryClothScene) with their results: one row a scene (its worst keyframe's
displacement under a change of the variant by 1e-3 and 1e-4 of itself, in tolerances; pass; miss), and the pass
rate of the well-conditioned scenes (moved under one tolerance by 1e-3) against the knife edges; and OUT.png (with
gnuplot): each scene's miss against how far 1e-3 of its change moves it, passes and failures apart.
Result files merge as in scripts/reachable_classes.py (a scene counts once, as the last file measured it).

Usage: scripts/reachable_conditioning.py OUT.csv CONDITIONING.csv IN.csv ..."""
import csv, os, shutil, subprocess, sys, tempfile

sys.dont_write_bytecode = True  # no __pycache__ beside the scripts
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from reachable_classes import merged_rows

if len(sys.argv) < 4:
    raise SystemExit(__doc__)
result = merged_rows(sys.argv[3:])
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

if shutil.which("gnuplot"):
    png = os.path.splitext(sys.argv[1])[0] + ".png"
    with tempfile.TemporaryDirectory() as tmp:
        data = {}
        for passed in ("yes", "no"):
            data[passed] = os.path.join(tmp, passed + ".dat")
            with open(data[passed], "w") as f:
                for r in rows:
                    if r[5] == passed:  # misses below 1e-3 tolerances drawn at 1e-3
                        f.write(f"{r[2]} {max(float(r[6]), 1e-3)} {r[0]}\n")
        script = f"""set terminal pngcairo size 900,640 font ',11'
set output '{png}.part'
set logscale xy
set xlabel 'worst keyframe moved by 1e-3 of the change the variant differs by (tolerances)'
set ylabel 'miss after optimising (tolerances; below 1e-3 drawn at 1e-3)'
set title 'generated cloth scenes: knife edges (right of 1) and the misses'
set arrow from 1, graph 0 to 1, graph 1 nohead dt 2 lc rgb 'gray40'
set arrow from graph 0, first 1 to graph 1, first 1 nohead dt 2 lc rgb 'gray40'
set key top left
plot '{data["yes"]}' using 1:2 with points pt 7 ps 1.1 lc rgb '#2a9d4a' title 'passed', \\
     '{data["no"]}' using 1:2 with points pt 5 ps 1.3 lc rgb '#c0392b' title 'failed', \\
     '{data["no"]}' using 1:2:3 with labels offset 0,1 font ',9' notitle
"""
        subprocess.run(["gnuplot"], input=script, text=True, check=True)
    os.replace(png + ".part", png)
