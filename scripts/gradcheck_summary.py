#!/usr/bin/env python3
"""Summarises a gradcheck_table.py CSV as the README's markdown table: one row per scene and adjoint, or
with `rows`, one row per check (the long-horizon table).

Usage: scripts/gradcheck_summary.py tests/results/gradcheck_scenes.csv
       scripts/gradcheck_summary.py tests/results/long_horizon.csv rows"""
import csv, sys
from collections import OrderedDict

rows = list(csv.DictReader(open(sys.argv[1])))
if sys.argv[2:] == ["rows"]:
    print("| steps | adjoint | checked (kinks) | max_rel_error | cosine | ‖adjoint − fd‖/‖fd‖ | fd_spread | gradient norm |")
    print("|---|---|---|---|---|---|---|---|")
    for r in rows:
        print(f"| {r['steps']} | {r['adjoint']} | {r['checked']} ({r['kinks']}) | {float(r['max_rel_error']):.1e} | "
              f"{float(r['cosine']):.7f} | {float(r['rel_error_norm']):.1e} | {float(r['fd_spread']):.1e} | "
              f"{float(r['grad_norm']):.2g} |")
    sys.exit(0)
groups = OrderedDict()
for r in rows:
    groups.setdefault((r["scene"], r["adjoint"]), []).append(r)
print("| scene | h (frames) | adjoint | checks | max_rel_error, worst | checks ≤ 1e-6 | largest fd_spread | lowest cosine | kinks |")
print("|---|---|---|---|---|---|---|---|---|")
for (scene, adjoint), g in groups.items():
    steps = OrderedDict()
    for r in g:
        steps.setdefault(r["dt"], set()).add(r["frames"])
    label = lambda frames: "/".join("all" if n == "0" else n for n in sorted(frames))  # 0: the scene's own
    h = ", ".join(f"{dt} ({label(f)})" for dt, f in steps.items())
    err = [float(r["max_rel_error"]) for r in g]
    kinks = sum(int(r["kinks"]) for r in g)
    samples = sum(int(r["kinks"]) + int(r["checked"]) for r in g)
    print(f"| {scene.removesuffix('.json')} | {h} | {adjoint} | {len(g)} | {max(err):.1e} | "
          f"{sum(e <= 1e-6 for e in err)} of {len(g)} | {max(float(r['fd_spread']) for r in g):.1e} | "
          f"{min(float(r['cosine']) for r in g):.6f} | {kinks} of {samples} |")
