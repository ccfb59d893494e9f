#!/usr/bin/env python3
"""Each stage's best evaluation in a run's log.txt: its evaluations, stop (from report.json), objective and
gradient norm, keyframe terms (at the stage's weights) and effort, and how much the best objective fell over the stage's last tenth.

Usage: stage_terms.py RUN_DIR...   (run directories of `keyframe optimize`)"""
import json, re, sys

for d in sys.argv[1:]:
    stages, order = {}, []
    for line in open(d + "/log.txt"):
        m = re.match(r"(?:stage (\d+) )?eval\s+\d+\s+phi (\S+)\s+(\|g\| \S+\s+.*?effort \S+)", line)
        if not m:
            continue
        s = m.group(1) or "1"
        if s not in stages:
            stages[s] = []
            order.append(s)
        stages[s].append((float(m.group(2)), m.group(3)))
    results = json.load(open(d + "/report.json"))["stage_results"]
    print(d)
    for s, r in zip(order, results):
        v = stages[s]
        best = [min(p for p, _ in v[: i + 1]) for i in range(len(v))]
        t = max(1, len(v) // 10)
        fall = best[-1] / best[len(v) - 1 - t] if len(v) > 1 else 1.0
        phi, terms = min(v, key=lambda x: x[0])
        print("  stage %s: %d evaluations (%s), best %.4g, last tenth x%.3f; %s" %
              (s, len(v), r["status"], phi, fall, " ".join(terms.split())))
