#!/usr/bin/env python3
"""What isolating assimp costs: `keyframe inspect FILE` on the character files, and `keyframe inspect SCENE`
of a mesh cloth (scenes/robustness/tablecloth-sphere.json with its tablecloth written as PLY, which assimp
reads), timed with a build that imports in process (BEFORE, e.g. main before the isolation) and one that
imports in a forked child (AFTER), runs alternated; writes file,build,runs,median_s,min_s (CSV) to OUT,
replacing the rows of the files it measured and keeping the others. WHICH: characters, cloth or all (the
default); BEFORE must read those files in process (characters: a build before 6a91060's isolation; cloth:
one before ea87b30).

  scripts/mesh_import_cost.py BEFORE_BINARY AFTER_BINARY OUT.csv [runs] [characters|cloth|all]"""
import csv, json, os, shutil, statistics, subprocess, sys, tempfile, time

FILES = ["assets/character/BCN_Epileptic.X", "/usr/share/assimp/models/X/Testwuson.X"]

if len(sys.argv) < 4:
    print(__doc__)
    sys.exit(2)
before, after, out = sys.argv[1:4]
runs = int(sys.argv[4]) if len(sys.argv) > 4 else 21
which = sys.argv[5] if len(sys.argv) > 5 else "all"
root = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))


def ply_cloth_scene(tmp):
    """The tablecloth scene with its mesh as ASCII PLY (the same vertices and faces as its OBJ)."""
    vertices, faces = [], []
    for line in open(os.path.join(root, "assets/cloth/tablecloth.obj")):
        p = line.split()
        if p and p[0] == "v":
            vertices.append(p[1:4])
        elif p and p[0] == "f":
            faces.append([str(int(c.split("/")[0]) - 1) for c in p[1:]])
    with open(os.path.join(tmp, "tablecloth.ply"), "w") as out:
        out.write("ply\nformat ascii 1.0\nelement vertex %d\nproperty float x\nproperty float y\nproperty float z\n"
                  "element face %d\nproperty list uchar int vertex_indices\nend_header\n" % (len(vertices), len(faces)))
        out.writelines(" ".join(v) + "\n" for v in vertices)
        out.writelines("%d %s\n" % (len(f), " ".join(f)) for f in faces)
    scene = json.load(open(os.path.join(root, "scenes/robustness/tablecloth-sphere.json")))
    scene.pop("$schema", None)
    scene["cloth"]["mesh"]["file"] = "tablecloth.ply"
    json.dump(scene, open(os.path.join(tmp, "tablecloth-ply.json"), "w"))
    return os.path.join(tmp, "tablecloth-ply.json")


tmp = tempfile.mkdtemp()
CASES = []
if which in ("characters", "all"):
    CASES += [(f, ["inspect", "--json", f if os.path.isabs(f) else os.path.join(root, f)]) for f in FILES]
if which in ("cloth", "all"):
    CASES.append(("scenes/robustness/tablecloth-sphere.json_mesh_as_ply", ["inspect", ply_cloth_scene(tmp)]))
measured = {f for f, _ in CASES}
rows = [r for r in csv.DictReader(open(out))] if os.path.exists(out) else []
rows = [r for r in rows if r["file"] not in measured]
for f, args in CASES:
    times = {"in_process": [], "isolated": []}
    for _ in range(runs):
        for build, binary in (("in_process", before), ("isolated", after)):
            t = time.perf_counter()
            subprocess.run([binary] + args, check=True, stdout=subprocess.DEVNULL)
            times[build].append(time.perf_counter() - t)
    for build, ts in times.items():
        rows.append({"file": f, "build": build, "runs": runs, "median_s": f"{statistics.median(ts):.4f}",
                     "min_s": f"{min(ts):.4f}"})
with open(out, "w", newline="") as fh:
    w = csv.DictWriter(fh, fieldnames=list(rows[0]))
    w.writeheader()
    w.writerows(rows)
shutil.rmtree(tmp)
