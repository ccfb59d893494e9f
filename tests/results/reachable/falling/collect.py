#!/usr/bin/env python3
"""One row per `keyframe optimize` run directory: its worst keyframe miss (in tolerances; the poncho's in cm
too), evaluations, CPU seconds (from RUN.time, written by `/usr/bin/time -f %U+%S -o RUN.time`), each stage's
evaluations, stop and the fall of its best objective over its last tenth, and the log's lines of the rule
("still falling at its limit ...").

Usage: collect.py OUT.csv VARIANT=RUN_DIR[,RUN_DIR...] ...   (the log is RUN_DIR.log: optimize's stdout)"""
import csv, json, re, sys


def stage_falls(log):
    stages, order = {}, []
    for line in open(log):
        m = re.match(r"(?:stage (\d+) )?eval\s+\d+\s+phi (\S+)", line)
        if m:
            s = m.group(1) or "1"
            if s not in stages:
                order.append(s)
            stages.setdefault(s, []).append(float(m.group(2)))
    out = []
    for s in order:
        v = stages[s]
        best = [min(v[: i + 1]) for i in range(len(v))]
        t = max(1, len(v) // 10)
        out.append(best[-1] / best[len(v) - 1 - t] if len(v) > 1 else 1.0)
    return out


rows = []
for arg in sys.argv[2:]:
    variant, dirs = arg.split("=", 1)
    for d in dirs.split(","):
        j = json.load(open(d + "/report.json"))
        judged = [k for k in j["keyframe_errors"] if k.get("judged")]
        worst = max(judged, key=lambda k: k["miss_after"])
        falls = stage_falls(d + ".log")
        stages = " ".join("%d:%s:x%.4f" % (s["evaluations"], s["status"].split(" ")[0].rstrip(":"), f)
                          for s, f in zip(j["stage_results"], falls))
        rule = [l.strip() for l in open(d + ".log") if l.startswith("still falling")]
        cpu = sum(float(x) for x in open(d + ".time").read().split()[-1].split("+"))
        rows.append({"scene": j["scene"] if isinstance(j["scene"], str) else d.rsplit("-", 2)[-1],
                     "variant": variant, "worst_miss": "%.4g" % worst["miss_after"],
                     "worst_error": worst["error_after"], "keyframe": worst["name"],
                     "met_all": all(k["met"] for k in judged), "evaluations": j["evaluations"],
                     "cpu_seconds": "%.1f" % cpu, "stages_evaluations_stop_fall": stages,
                     "rule_lines": " | ".join(rule)})
with open(sys.argv[1], "w", newline="") as f:
    w = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
    w.writeheader()
    w.writerows(rows)
