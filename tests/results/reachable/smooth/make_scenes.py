#!/usr/bin/env python3
"""Writes the scenes these runs optimised into OUT_DIR, each a committed scene with one change:
  NAME-direct.json    cloth.solver "direct" (cape-wuson-0..4, cape-0..6, poncho, poncho-lift)
  NAME-lead.json      optimizer.schedule: the forces of frames 40 to 45 per particle (150 evaluations), then
                      every frame's per particle (150) (cape-wuson-0, -2, -4: one keyframe, at frame 45)
  NAME-leadcg12.json  the same with cloth.cg_tolerance 1e-12
  NAME-lead35cg12.json    that with the first window from frame 35 (cape-wuson-0, -4)
  NAME-lead3cg12.json     that with windows from frames 40 (150), 30 (75), then every frame (75) (cape-wuson-0, -4)
Paths inside the scenes are made absolute, so OUT_DIR may be anywhere.

Usage: make_scenes.py OUT_DIR"""
import json, os, sys

if len(sys.argv) != 2:
    raise SystemExit(__doc__)
root = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "../../../.."))
out = sys.argv[1]
os.makedirs(out, exist_ok=True)


def load(path):
    s = json.load(open(path))
    s.pop("$schema", None)
    d = os.path.dirname(path)
    if "character" in s and not os.path.isabs(s["character"]["file"]):
        s["character"]["file"] = os.path.normpath(os.path.join(d, s["character"]["file"]))
    if isinstance(s["cloth"].get("mesh"), dict):
        s["cloth"]["mesh"]["file"] = os.path.normpath(os.path.join(d, s["cloth"]["mesh"]["file"]))
    return s


def write(s, name):
    json.dump(s, open(os.path.join(out, name + ".json"), "w"))


scenes = {n: os.path.join(root, "tests/results/reachable/scenes", n + ".json")
          for n in ["cape-wuson-%d" % i for i in range(5)] + ["cape-%d" % i for i in range(7)]}
scenes.update({n: os.path.join(root, "scenes/robustness", n + ".json") for n in ("poncho", "poncho-lift")})
for name, path in scenes.items():
    s = load(path)
    s["cloth"]["solver"] = "direct"
    write(s, name + "-direct")
lead = [{"substeps": 2, "max_evaluations": 150, "controls": {"kind": "per_frame", "from_frame": 40}},
        {"substeps": 2, "max_evaluations": 150}]
for i in (0, 2, 4):
    s = load(scenes["cape-wuson-%d" % i])
    s.setdefault("optimizer", {})["schedule"] = lead
    write(s, "cape-wuson-%d-lead" % i)
    s["cloth"]["cg_tolerance"] = 1e-12
    write(s, "cape-wuson-%d-leadcg12" % i)
    if i == 2:
        continue
    s["optimizer"]["schedule"] = [dict(lead[0], controls={"kind": "per_frame", "from_frame": 35}), lead[1]]
    write(s, "cape-wuson-%d-lead35cg12" % i)
    s["optimizer"]["schedule"] = [lead[0], {"substeps": 2, "max_evaluations": 75,
                                            "controls": {"kind": "per_frame", "from_frame": 30}},
                                  {"substeps": 2, "max_evaluations": 75}]
    write(s, "cape-wuson-%d-lead3cg12" % i)
