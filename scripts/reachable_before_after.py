#!/usr/bin/env python3
"""Compares two runs of `keyframe bench --only reachable` scene by scene: the worst miss (in tolerances),
evaluations, CPU seconds and pass of each, for the scenes both ran, and a last row with the pass counts and
the median and worst CPU seconds.

Usage: scripts/reachable_before_after.py OUT.csv BEFORE.csv[,BEFORE2.csv...] AFTER.csv[,AFTER2.csv...]"""
import csv, statistics, sys

if len(sys.argv) != 4:
    raise SystemExit(__doc__)


def num(v, fmt):
    return fmt % float(v) if v != "" else "–"  # a job cut before its first evaluation measured nothing


def rows(files):
    return {r["scene"]: r for f in files.split(",") for r in csv.DictReader(open(f))}


before, after = rows(sys.argv[2]), rows(sys.argv[3])
names = sorted((n for n in after if n in before), key=lambda n: (n.rsplit("-", 1)[0], int(n.rsplit("-", 1)[1])))
fields = ["scene", "miss_before", "miss_after_before", "pass_before", "cpu_seconds_before", "miss_after", "pass",
          "evaluations", "cpu_seconds", "outcome"]
with open(sys.argv[1], "w", newline="") as out:
    w = csv.writer(out)
    w.writerow(fields)
    for n in names:
        b, a = before[n], after[n]
        w.writerow([n, num(b["miss_before"], "%.2f"), num(b["miss_after"], "%.3g"), b["pass"],
                    "%.1f" % float(b["cpu_seconds"]), num(a["miss_after"], "%.3g"), a["pass"], a["evaluations"],
                    "%.1f" % float(a["cpu_seconds"]), a["outcome"]])
    cb = [float(before[n]["cpu_seconds"]) for n in names]
    ca = [float(after[n]["cpu_seconds"]) for n in names]
    w.writerow(["all (%d)" % len(names), "", "", "%d passed" % sum(before[n]["pass"] == "yes" for n in names),
                "median %.1f, worst %.1f" % (statistics.median(cb), max(cb)) if names else "", "",
                "%d passed" % sum(after[n]["pass"] == "yes" for n in names), "",
                "median %.1f, worst %.1f" % (statistics.median(ca), max(ca)) if names else "", ""])
