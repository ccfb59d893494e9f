#!/usr/bin/env python3
"""Summarises `keyframe bench --only adjoint`'s adjoint.csv as the README's table: exact against swap per
scene (gradient cost, its direction against finite differences, the keyframe error reached in the same
wall time; the lower error in bold, and a run the line search ended early says when).

Usage: scripts/adjoint_summary.py tests/results/bench/adjoint.csv"""
import csv, sys

rows = list(csv.DictReader(open(sys.argv[1])))
by = {(r["scene"], r["adjoint"]): r for r in rows}
budget = max(float(r["optimise_seconds"]) for r in rows)
print("| scene | gradient, exact / swap | exact ÷ swap | cosine vs differences, exact / swap | "
      "keyframe error at the end, exact / swap (evaluations) |")
print("|---|---|---|---|---|")
for scene in dict.fromkeys(r["scene"] for r in rows):
    e, s = by[(scene, "exact")], by[(scene, "swap")]
    label = f"{scene} ({int(e['steps'])} steps, {int(e['control_variables']):,} variables)"
    grad = f"{float(e['gradient_seconds']):.3f} / {float(s['gradient_seconds']):.3f} s"
    ratio = f"{float(e['gradient_seconds']) / float(s['gradient_seconds']):.2f}"
    cos = f"{float(e['cosine']):.6f} / {float(s['cosine']):.6f}"

    def error(r, best):
        text = f"{float(r['final_error']):.2g}"
        text = f"**{text}**" if best else text
        note = f", stopped at {float(r['optimise_seconds']):.0f} s" if float(r["optimise_seconds"]) < 0.9 * budget else ""
        return f"{text} ({r['evaluations']}{note})"

    ee, se = float(e["final_error"]), float(s["final_error"])
    print(f"| {label} | {grad} | {ratio} | {cos} | {error(e, ee < se)} / {error(s, se < ee)} |")
