#!/usr/bin/env python3
"""Merges reachable.csv files of `keyframe bench --only reachable` runs (a run split over classes, or cut off
before its class table) into one table a class: scenes, passed, pass rate, median evaluations, median and
worst wall seconds, median and worst CPU seconds, and a row "all". A scene in more than one file counts once,
as the last file measured it (a rerun of some scenes at a later commit replaces their earlier rows).

Usage: scripts/reachable_classes.py OUT.csv IN.csv ..."""
import csv, statistics, sys


def merged_rows(files):
    """The rows of reachable.csv files by scene, each as the last file measured it."""
    by_scene = {}
    for f in files:
        for r in csv.DictReader(open(f)):
            by_scene[r["scene"]] = r
    return by_scene


def main():
    if len(sys.argv) < 3:
        raise SystemExit(__doc__)
    rows = list(merged_rows(sys.argv[2:]).values())
    groups = {}
    for r in rows:
        groups.setdefault(r["class"], []).append(r)
    groups = dict(sorted(groups.items()))
    groups["all"] = rows
    fields = ["class", "scenes", "passed", "pass_rate", "median_evaluations", "median_seconds", "worst_seconds",
              "median_cpu_seconds", "worst_cpu_seconds"]
    with open(sys.argv[1], "w", newline="") as out:
        w = csv.writer(out)
        w.writerow(fields)
        for kind, rs in groups.items():
            secs = [float(r["seconds"]) for r in rs]
            cpu = [float(r["cpu_seconds"]) for r in rs]
            passed = sum(r["pass"] == "yes" for r in rs)
            w.writerow([kind, len(rs), passed, "%.3f" % (passed / len(rs)),
                        "%g" % statistics.median(float(r["evaluations"]) for r in rs),
                        "%.1f" % statistics.median(secs), "%.1f" % max(secs),
                        "%.1f" % statistics.median(cpu), "%.1f" % max(cpu)])


if __name__ == "__main__":
    main()
