#!/usr/bin/env python3
"""Adds to capped_outputs.sh's CSV whether each scene's report.json says the same before and after: its
measures, keyframe_errors, diagnosis and cape_end_state (timings left out). A run the wall-time limit cut
(exit 124, or 137 when it was killed 20 s after the timeout's TERM) is "timeout" and its scene "not_compared".
Usage: tests/results/architecture/compare_reports.py OUT_ROOT CSV > WITH_REPORTS.csv"""
import json, sys, os, csv
root = sys.argv[1]
rows = list(csv.DictReader(open(sys.argv[2])))
out = csv.writer(sys.stdout)
fields = list(rows[0].keys()) + ["report_measures_identical"] if rows else []
out.writerow(fields)
for r in rows:
    for side in ("exit_before", "exit_after"):
        if r[side] in ("124", "137"): r[side] = "timeout"
    if "timeout" in (r["exit_before"], r["exit_after"]): r["identical"] = "not_compared"
    n = r["scene"].replace("/", "_")[:-5]
    def load(side):
        p = os.path.join(root, f"{side}_{n}", "report.json")
        if not os.path.exists(p): return None
        j = json.load(open(p))
        return {k: j.get(k) for k in ("measures", "keyframe_errors", "diagnosis", "cape_end_state")}
    a, b = load("before"), load("after")
    same = "no_report" if a is None and b is None else ("yes" if a == b else "no")
    if r["identical"] == "not_compared": same = "not_compared"
    out.writerow(list(r.values()) + [same])
