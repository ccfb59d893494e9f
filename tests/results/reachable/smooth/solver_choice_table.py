#!/usr/bin/env python3
"""solver_choice.csv from Google Benchmark's JSON of BM_ClothForwardAdjointStep (tests/bench/
cloth_solver_choice_bench.cpp): CPU ms per forward + adjoint step (median of the repetitions) for PCG and the
direct solve at each sheet size, and their ratio.

Usage: solver_choice_table.py BENCH.json OUT.csv"""
import csv, json, sys

if len(sys.argv) != 3:
    raise SystemExit(__doc__)
rows = {}
for b in json.load(open(sys.argv[1]))["benchmarks"]:
    if b.get("aggregate_name") != "median":
        continue
    n, solver = b["run_name"].split("/")[1:3]
    ms = b["cpu_time"] / 10  # ten steps an iteration, cpu_time in ms
    rows.setdefault(int(n), {})["direct" if solver == "1" else "pcg"] = ms
with open(sys.argv[2], "w", newline="") as out:
    w = csv.writer(out)
    w.writerow(["n", "particles", "pcg_cpu_ms_per_step", "direct_cpu_ms_per_step", "direct_over_pcg"])
    for n in sorted(rows):
        p, d = rows[n].get("pcg"), rows[n].get("direct")
        w.writerow([n, n * n, "%.3f" % p if p else "", "%.3f" % d if d else "", "%.2f" % (d / p) if p and d else ""])
