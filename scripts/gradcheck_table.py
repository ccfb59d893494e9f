#!/usr/bin/env python3
"""Runs `keyframe gradcheck` over a grid of scenes, frame counts, steps, perturbations and adjoints and
writes one CSV row per run (the JSON the command prints, flattened).

Usage: scripts/gradcheck_table.py OUT.csv --scenes A.json[,B.json] [--frames 3[,10]] [--dt 1/30[,1/60]]
                                  [--perturb 0[,0.01]] [--adjoint exact[,swap]] [--samples N] [--eps E]
                                  [--solver direct|scene]
KEYFRAME=PATH runs another build. Regenerates the gradient tables of the README (see its "Accuracy of the gradients")."""
import argparse, csv, itertools, json, os, subprocess, sys
from fractions import Fraction

here = os.path.dirname(os.path.abspath(__file__))
keyframe = os.environ.get("KEYFRAME", os.path.join(here, "..", "build", "release", "keyframe"))
p = argparse.ArgumentParser()
p.add_argument("out")
p.add_argument("--scenes", required=True)
p.add_argument("--frames", default="0")
p.add_argument("--dt", default="0")
p.add_argument("--perturb", default="0,0.01,0.1")
p.add_argument("--adjoint", default="exact")
p.add_argument("--samples", default="20")
p.add_argument("--eps", default="1e-4")
p.add_argument("--solver", default="direct", help="direct, or scene (the scene's own PCG and tolerance)")
a = p.parse_args()
split = lambda s: [x for x in s.split(",") if x]
columns = ["scene", "frames", "dt", "perturb", "adjoint", "steps", "h", "checked", "kinks", "max_rel_error",
           "cosine", "rel_error_norm", "fd_spread", "grad_norm", "phi", "seconds"]
rows = []
for scene, frames, dt, perturb, adjoint in itertools.product(split(a.scenes), split(a.frames), split(a.dt),
                                                             split(a.perturb), split(a.adjoint)):
    cmd = [keyframe, "gradcheck", scene, "--perturb", perturb, "--adjoint", adjoint, "--samples", a.samples,
           "--eps", a.eps, "--solver", a.solver]
    if int(frames) > 0:
        cmd += ["--frames", frames]
    if dt != "0":
        cmd += ["--dt", repr(float(Fraction(dt)))]
    import time
    t0 = time.time()
    run = subprocess.run(cmd, capture_output=True, text=True)
    if run.returncode != 0:
        sys.exit(f"{' '.join(cmd)}: {run.stderr.strip()}")
    j = json.loads(run.stdout.strip().splitlines()[-1])
    row = {"scene": os.path.basename(scene), "frames": frames, "dt": dt, "perturb": perturb, "adjoint": adjoint,
           "seconds": round(time.time() - t0, 2)}
    row.update({k: j[k] for k in columns if k in j})
    rows.append(row)
    print(",".join(str(row.get(c, "")) for c in columns), flush=True)
tmp = a.out + ".tmp"
with open(tmp, "w", newline="") as f:
    w = csv.DictWriter(f, fieldnames=columns)
    w.writeheader()
    w.writerows(rows)
os.replace(tmp, a.out)
