#!/usr/bin/env python3
"""Cost at equal accuracy from the solver bench's step settings (solver_step_settings.csv).

For each target error (the mean per-frame RMS distance, mm, of each size's default bake: theta 1, the default
ramp, tolerance 1e-4, the file's first row per size), the cheapest setting of each size whose error is at most
the target, and the larger size's time over the smaller's. Every size was run with the same settings.

Usage: scripts/equal_accuracy.py FILE             the markdown table
       scripts/equal_accuracy.py FILE ratio=N     the ratio at the target of size N's default (%.2f)"""
import csv, sys

if len(sys.argv) < 2:
    raise SystemExit(__doc__)
rows = list(csv.DictReader(open(sys.argv[1])))
sizes = sorted({int(r["n"]) for r in rows})
if len(sizes) != 2:
    raise SystemExit(f"equal_accuracy.py: {sys.argv[1]}: expected two sizes, got {sizes}")
default = {n: next(r for r in rows if int(r["n"]) == n) for n in sizes}


def cheapest(n, target):
    ok = [r for r in rows if int(r["n"]) == n and r["frame_rms_mm"] != "nan" and float(r["frame_rms_mm"]) <= target]
    return min(ok, key=lambda r: float(r["forward_s"])) if ok else None


def setting(r):
    return f"θ {float(r['theta']):g}, ramp {float(r['transverse_ramp']):g}, tol {float(r['tolerance']):g}"


if len(sys.argv) > 2:
    key, _, value = sys.argv[2].partition("=")
    if key != "ratio" or int(value) not in sizes:
        raise SystemExit(f"equal_accuracy.py: expected ratio=N with N one of {sizes}, got {sys.argv[2]!r}")
    target = float(default[int(value)]["frame_rms_mm"])
    a, b = cheapest(sizes[0], target), cheapest(sizes[1], target)
    print("%.2f" % (float(b["forward_s"]) / float(a["forward_s"])) if a and b else "–")
    raise SystemExit(0)

small, large = sizes
print(f"| target error (mm) | {small}²: cheapest setting | ms a step | error (mm) "
      f"| {large}²: cheapest setting | ms a step | error (mm) | {large}² ÷ {small}² |")
print("|---|---|---|---|---|---|---|---|")
for n in sizes:
    target = float(default[n]["frame_rms_mm"])
    a, b = cheapest(small, target), cheapest(large, target)
    cells = [f"{target:.1f} ({n}² default)"]
    for r in (a, b):
        cells += [setting(r), f"{float(r['ms_per_step']):.2f}", f"{float(r['frame_rms_mm']):.1f}"] if r else ["none", "–", "–"]
    cells.append(f"{float(b['forward_s']) / float(a['forward_s']):.2f}" if a and b else "–")
    print("| " + " | ".join(cells) + " |")
