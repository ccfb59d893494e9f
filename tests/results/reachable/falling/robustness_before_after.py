#!/usr/bin/env python3
"""The robustness suite before and after, scene by scene: worst miss (in tolerances), pass, evaluations and CPU
seconds. Scenes the before file lacks have empty before columns.

Usage: robustness_before_after.py OUT.csv BEFORE/robustness.csv AFTER/robustness.csv"""
import csv, sys

if len(sys.argv) != 4:
    raise SystemExit(__doc__)
old = {r["scene"]: r for r in csv.DictReader(open(sys.argv[2]))}
rows = []
for r in csv.DictReader(open(sys.argv[3])):
    o = old.get(r["scene"])
    rows.append({"scene": r["scene"], "miss_before": "%.3g" % float(o["miss_after"]) if o else "",
                 "pass_before": o["pass"] if o else "",
                 "cpu_seconds_before": "%.1f" % float(o["cpu_seconds"]) if o else "",
                 "miss_after": "%.3g" % float(r["miss_after"]), "pass": r["pass"], "evaluations": r["evaluations"],
                 "cpu_seconds": "%.1f" % float(r["cpu_seconds"])})
with open(sys.argv[1], "w", newline="") as f:
    w = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
    w.writeheader()
    w.writerows(rows)
