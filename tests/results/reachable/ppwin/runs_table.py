#!/usr/bin/env python3
"""One row per optimize run directory: the plan it ran under, its worst keyframe miss (tolerances), evaluations,
CPU seconds (from a /usr/bin/time -f %U+%S file beside it, RUN.time) and its stages (evaluations:kind:stop).

  runs_table.py OUT.csv PLAN=RUN_DIR [PLAN=RUN_DIR ...]"""
import csv, json, os, sys

STOPS = {"evaluation limit": "limit", "line search made no progress": "stalled", "converged": "converged",
         "keyframes reached": "reached"}


def stop(status):
    for k, v in STOPS.items():
        if k in status:
            return v
    return status.split()[0]


rows = []
for arg in sys.argv[2:]:
    plan, run = arg.split("=", 1)
    r = json.load(open(os.path.join(run, "report.json")))
    errors = [e for e in r["keyframe_errors"] if e.get("judged", True)]
    worst = max(errors, key=lambda e: e["miss_after"])
    cpu = ""
    if os.path.exists(run.rstrip("/") + ".time"):
        line = [l for l in open(run.rstrip("/") + ".time") if "+" in l][-1]
        cpu = "%.1f" % sum(float(x) for x in line.strip().split("+"))
    stages = " ".join("%d:%s:%s" % (s["evaluations"], s["kind"], stop(s["status"])) for s in r["stage_results"])
    rows.append({"scene": os.path.basename(r["scene"]).replace(".json", "") if isinstance(r["scene"], str) else run,
                 "plan": plan, "keyframe": worst["name"], "miss_before": "%.3g" % worst["miss_before"],
                 "miss_after": "%.3g" % worst["miss_after"], "error_after": worst["error_after"],
                 "evaluations": r["evaluations"], "cpu_seconds": cpu, "stages": stages})
with open(sys.argv[1], "w", newline="") as f:
    w = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
    w.writeheader()
    w.writerows(rows)
