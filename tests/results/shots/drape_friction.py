#!/usr/bin/env python3
"""The drape onto human.zae unaided at several body frictions: keyframe simulate of each scene, then its
keyframe's miss (report.json) and the sheet's centre of mass at the keyframe's frame (export --format csv).

  python3 tests/results/shots/drape_friction.py KEYFRAME OUT.csv SCENE...   (each SCENE a drape-human variant)"""
import csv, json, os, subprocess, sys, tempfile

keyframe, out, scenes = sys.argv[1], sys.argv[2], sys.argv[3:]
rows = []
for scene in scenes:
    spec = json.load(open(scene))
    frame = spec["objectives"][0]["frame"]
    with tempfile.TemporaryDirectory() as tmp:
        run = os.path.join(tmp, "run")
        subprocess.run([keyframe, "simulate", scene, "--out", run], check=True, capture_output=True)
        subprocess.run([keyframe, "export", run, "--format", "csv"], check=True, capture_output=True)
        report = json.load(open(os.path.join(run, "report.json")))
        pts = [r for r in csv.DictReader(open(os.path.join(run, "export", "trajectory.csv"))) if int(r["frame"]) == frame]
    com = [sum(float(r[a]) for r in pts) / len(pts) for a in "xyz"]
    rows.append({"scene": os.path.basename(scene), "body_friction": spec["character"].get("body", {}).get("friction", 0),
                 "frame": frame, "miss_cm": round(report["keyframe_errors"][0]["miss_before"], 2),
                 "com_x": round(com[0], 4), "com_y": round(com[1], 4), "com_z": round(com[2], 4),
                 "min_body_distance_m": round(report["run_stats"]["min_body_distance"], 4)})
with open(out, "w", newline="") as f:
    w = csv.DictWriter(f, fieldnames=list(rows[0]))
    w.writeheader()
    w.writerows(rows)
