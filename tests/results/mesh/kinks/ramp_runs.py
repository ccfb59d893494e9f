#!/usr/bin/env python3
"""The character scenes' runs at another cloth.contact_ramp (0.5 is the default), one row per report.json:

  python3 ramp_runs.py OUT.csv SCENE:RAMP:REPORT...
miss is the worst keyframe's miss in tolerances (1 tolerance = 1 cm here); gradient_growth is the report's
(sensitivity: how much the gradient per frame grows from the keyframe back)."""
import csv, json, sys

with open(sys.argv[1], "w", newline="") as f:
    w = csv.writer(f)
    w.writerow(["scene", "contact_ramp", "miss", "reached", "evaluations", "gradient_growth"])
    for arg in sys.argv[2:]:
        scene, ramp, path = arg.split(":")
        r = json.load(open(path))
        errors = r["keyframe_errors"]
        miss = max(e["miss_after"] for e in errors)
        w.writerow([scene, ramp, "%.3g" % miss, "yes" if all(e["met"] for e in errors) else "no", r["evaluations"],
                    "%.2g" % r["sensitivity"]["gradient_growth"]])
