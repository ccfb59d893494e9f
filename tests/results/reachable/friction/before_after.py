#!/usr/bin/env python3
"""Joins the suite's rows on main (ordered-a/b) with this run's (friction/a, friction/b) by scene:
python3 tests/results/reachable/friction/before_after.py > tests/results/reachable/friction/before_after.csv"""
import csv, glob, os

here = os.path.dirname(os.path.abspath(__file__))
before = {}
for f in glob.glob(os.path.join(here, "..", "ordered-*", "reachable.csv")):
    for r in csv.DictReader(open(f)):
        before[r["scene"]] = r
after, seen = [], set()  # a scene measured twice (the same controls both times) is listed once
for f in sorted(glob.glob(os.path.join(here, "*", "reachable.csv"))):
    for r in csv.DictReader(open(f)):
        if r["scene"] not in seen:
            seen.add(r["scene"])
            after.append(r)
# Each side's worst keyframe (in tolerances), uncontrolled and optimised.
cols = ["scene", "friction", "keyframes", "keyframe_before", "uncontrolled_before", "miss_before", "outcome_before",
        "pass_before", "keyframe_after", "uncontrolled_after", "miss_after", "evaluations_after", "cpu_seconds_after",
        "outcome_after", "pass_after"]
print(",".join(cols))
for r in after:
    b = before.get(r["scene"], {})
    print(",".join([r["scene"], r["friction"], r["keyframes"], b.get("keyframe", ""), b.get("miss_before", ""),
                    b.get("miss_after", ""), b.get("outcome", ""), b.get("pass", ""), r["keyframe"], r["miss_before"], r["miss_after"],
                    r["evaluations"], r["cpu_seconds"], r["outcome"], r["pass"]]))
