#!/usr/bin/env python3
"""Where a character's body is near a keyframe's mark, frame by frame: from a run exported as OBJ
(`keyframe export RUN --format obj`), for each frame the body's z range within an x and y box, and the
nearest body vertex to the mark. Says whether a mark lies where a limb sweeps (a mark the body crosses late
in the clip is one the cloth must be carried around, not pulled straight to).

Usage: scripts/body_near_mark.py EXPORT_DIR X Y Z XMIN XMAX YMIN YMAX FRAME ..."""
import math, os, sys


def body_vertices(path):
    """The vertices of the OBJ's "body" group (those its faces use)."""
    vertices, used, group = [], set(), None
    for line in open(path):
        if line.startswith("v "):
            vertices.append(tuple(map(float, line.split()[1:4])))
        elif line.startswith("g "):
            group = line[2:].strip()
        elif line.startswith("f ") and group == "body":
            used.update(int(t.split("/")[0]) - 1 for t in line.split()[1:])
    return [vertices[i] for i in sorted(used)]


if len(sys.argv) < 10:
    raise SystemExit(__doc__)
mark = tuple(map(float, sys.argv[2:5]))
xmin, xmax, ymin, ymax = map(float, sys.argv[5:9])
print("frame,body_z_min_in_box,body_z_max_in_box,nearest_body_vertex_to_mark_m")
for frame in map(int, sys.argv[9:]):
    body = body_vertices(os.path.join(sys.argv[1], "frame_%04d.obj" % frame))
    box = [v[2] for v in body if xmin < v[0] < xmax and ymin < v[1] < ymax]
    near = min(math.dist(v, mark) for v in body)
    zs = "%.3f,%.3f" % (min(box), max(box)) if box else ","
    print("%d,%s,%.3f" % (frame, zs, near))
