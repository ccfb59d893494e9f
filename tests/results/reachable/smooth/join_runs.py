#!/usr/bin/env python3
"""Joins this directory's optimize runs (runs.csv: one row per run, written by run_cut.py) with the same
scenes' runs at the scene's PCG from the committed suites (the generated suite's after-drag/a and /b, the
robustness suite at 72ced21), scene by scene.

Usage: join_runs.py RUNS.csv OUT.csv   (a run is named SCENE-VARIANT: cape-wuson-0-direct, cape-wuson-0-lead)"""
import csv, os, sys

if len(sys.argv) != 3:
    raise SystemExit(__doc__)
runs_csv, out_csv = sys.argv[1:]
here = os.path.dirname(os.path.abspath(__file__))
res = os.path.normpath(os.path.join(here, "../.."))
base = {}
for f in ("reachable/after-drag/a/reachable.csv", "reachable/after-drag/b/reachable.csv"):
    for r in csv.DictReader(open(os.path.join(res, f))):
        base[r["scene"]] = dict(particles=r["particles"], miss=r["miss_after"], passed=r["pass"],
                                evaluations=r["evaluations"], cpu=r["cpu_seconds"])
for r in csv.DictReader(open(os.path.join(res, "robustness/main-72ced21/robustness.csv"))):
    if r["scene"].startswith("poncho"):
        base[r["scene"]] = dict(particles="348", miss=r["miss_after"], passed=r["pass"],
                                evaluations=r["evaluations"], cpu=r["cpu_seconds"])


def per_eval(cpu, ev):
    return "%.3f" % (float(cpu) / float(ev)) if cpu and ev and float(ev) > 0 else ""


with open(out_csv, "w", newline="") as out:
    w = csv.writer(out)
    w.writerow(["scene", "variant", "particles", "pcg_miss", "pcg_pass", "pcg_evaluations", "pcg_cpu_seconds",
                "pcg_cpu_per_evaluation", "miss", "pass", "evaluations", "cpu_seconds", "cpu_per_evaluation",
                "cpu_per_evaluation_ratio", "cut", "status", "load_1min"])
    def order(r):  # cape-wuson-0 .. -4, cape-0 .. -6, poncho, poncho-lift; a scene's variants as they ran
        name = max((n for n in base if r["run"].startswith(n + "-")), key=len)
        head, _, tail = name.rpartition("-")
        return (0, head, int(tail)) if tail.isdigit() else (1, name, 0)

    for r in sorted(csv.DictReader(open(runs_csv)), key=order):
        name = max((n for n in base if r["run"].startswith(n + "-")), key=len)
        variant = r["run"][len(name) + 1:]
        b = base[name]
        pe, de = per_eval(b["cpu"], b["evaluations"]), per_eval(r["cpu_seconds"], r["evaluations"])
        w.writerow([name, variant, b["particles"], "%.3g" % float(b["miss"]), b["passed"], b["evaluations"],
                    "%.1f" % float(b["cpu"]), pe, r["miss_after"], r["pass"], r["evaluations"], r["cpu_seconds"], de,
                    "%.2f" % (float(de) / float(pe)) if pe and de else "", r["cut"], r["status"], r["load_1min"]])
