#!/usr/bin/env python3
"""Measures optimisation strategies on cloth scenes: each scene is optimised once per strategy (its
optimizer block overridden as below) and one row per run goes to the CSV: keyframe error before (the
uncontrolled motion) and after, evaluations, seconds, pass (every keyframe within 1 cm, or 1 % of the
sheet's larger side, whichever is larger) and the run's status line.

  single      one stage over the scene's controls, NLopt's own first step (the behaviour before strategies)
  first_step  one stage, first trial step scaled to the controls' units (optimizer.first_step automatic)
  windows     the staged strategy (optimizer.strategy auto) with NLopt's own first step
  default     the staged strategy and the scaled first step: what a scene gets with no optimizer keys

Usage (from the repository root, after building):
  python3 scripts/measure_strategies.py OUT.csv SCENE.json... [--strategies a,b] [--max-evaluations N]
"""
import argparse
import csv
import json
import os
import subprocess
import sys
import tempfile
import time

STRATEGIES = {
    "single": {"strategy": "single", "first_step": 0},
    "first_step": {"strategy": "single"},
    "windows": {"first_step": 0},
    "default": {},
}


def keyframe_errors(report):
    """(frame, type, error in m) of every position / centre-of-mass keyframe measure."""
    out = []
    for m in report.get("measures", []):
        if m.get("type") == "position" and "rms_error" in m:
            out.append((m["frame"], "position", m["rms_error"]))
        elif m.get("type") == "center_of_mass" and "error" in m:
            out.append((m["frame"], "center_of_mass", m["error"]))
    return out


def run(keyframe, scene, overrides, max_evals, workdir, tag):
    name = os.path.splitext(os.path.basename(scene))[0]
    with open(scene) as f:
        s = json.load(f)
    s.setdefault("optimizer", {}).update(overrides)
    if max_evals is not None:
        s["optimizer"]["max_evaluations"] = max_evals
    # The variant lives beside the original so relative paths (assets, runs) still resolve.
    variant = os.path.join(os.path.dirname(os.path.abspath(scene)), ".%s.%s.json" % (name, tag))
    with open(variant, "w") as f:
        json.dump(s, f)
    out = os.path.join(workdir, name + "-" + tag)
    try:
        t0 = time.time()
        p = subprocess.run([keyframe, "optimize", variant, "--out", out, "--quiet"], capture_output=True, text=True)
        seconds = time.time() - t0
    finally:
        os.remove(variant)
    report_path = os.path.join(out, "report.json")
    if not os.path.exists(report_path):
        sys.exit("%s (%s): no report; exit %d: %s" % (scene, tag, p.returncode, p.stderr.strip()[-300:]))
    with open(report_path) as f:
        report = json.load(f)
    last = [l for l in p.stdout.strip().splitlines() if l.strip()]
    return report, seconds, p.returncode, (last[-1] if last else "")


def size_of(scene):
    with open(scene) as f:
        c = json.load(f).get("cloth", {})
    return max(c.get("width", 1.0), c.get("height", 1.0))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("csv")
    ap.add_argument("scenes", nargs="+")
    ap.add_argument("--strategies", default=",".join(STRATEGIES))
    ap.add_argument("--max-evaluations", type=int, default=None)
    ap.add_argument("--keyframe", default="build/release/keyframe")
    a = ap.parse_args()
    fields = ["scene", "strategy", "error_before_m", "error_after_m", "tolerance_m", "pass", "evaluations",
              "seconds", "initial_objective", "final_objective", "exit_code", "status"]
    new = not os.path.exists(a.csv)
    with tempfile.TemporaryDirectory() as work, open(a.csv, "a", newline="") as f:
        w = csv.DictWriter(f, fieldnames=fields)
        if new:
            w.writeheader()
        for scene in a.scenes:
            tol = max(0.01, 0.01 * size_of(scene))
            before, _, _, _ = run(a.keyframe, scene, {"strategy": "single"}, 0, work, "before")
            err_before = max(e for _, _, e in keyframe_errors(before))
            for tag in a.strategies.split(","):
                report, seconds, code, status = run(a.keyframe, scene, STRATEGIES[tag], a.max_evaluations, work, tag)
                err_after = max(e for _, _, e in keyframe_errors(report))
                row = {"scene": os.path.splitext(os.path.basename(scene))[0], "strategy": tag,
                       "error_before_m": "%.4g" % err_before, "error_after_m": "%.4g" % err_after,
                       "tolerance_m": "%.4g" % tol, "pass": int(err_after <= tol),
                       "evaluations": report["evaluations"], "seconds": "%.1f" % seconds,
                       "initial_objective": "%.4g" % report["initial_objective"],
                       "final_objective": "%.4g" % report["final_objective"], "exit_code": code,
                       "status": report.get("status", "")}
                w.writerow(row)
                f.flush()
                print(row, flush=True)


if __name__ == "__main__":
    main()
