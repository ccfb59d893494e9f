#!/usr/bin/env python3
"""How deep a drape goes into the body, frame by frame: each particle's signed distance to the body mesh
(closest triangle, signed by that triangle's outward normal; negative inside), the deepest particle per frame,
and the run's control force on that particle along the body's inward normal (per_frame forces, controls.bin), or
for lattice forces the largest node force.

  python3 tests/results/shots/drape_penetration.py KEYFRAME OUT.csv LABEL=RUN_DIR...

Each RUN_DIR is a `keyframe optimize` or `keyframe simulate` run; it is exported (--format obj) first."""
import json, math, os, struct, subprocess, sys


def read_obj(path):
    """The vertices and each group's triangles of one exported frame (`g cloth`, `g body`)."""
    v, groups, g = [], {}, None
    for line in open(path):
        w = line.split()
        if not w:
            continue
        if w[0] == "v":
            v.append(tuple(float(a) for a in w[1:4]))
        elif w[0] == "g":
            g = w[1]
        elif w[0] == "f":
            idx = [int(a.split("/")[0]) - 1 for a in w[1:]]
            for k in range(1, len(idx) - 1):
                groups.setdefault(g, []).append((idx[0], idx[k], idx[k + 1]))
    return v, groups


def sub(a, b): return (a[0] - b[0], a[1] - b[1], a[2] - b[2])
def dot(a, b): return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
def axpy(a, s, d): return (a[0] + s * d[0], a[1] + s * d[1], a[2] + s * d[2])
def cross(a, b): return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def closest_on_triangle(p, a, b, c):
    """Ericson, Real-Time Collision Detection 5.1.5."""
    ab, ac, ap = sub(b, a), sub(c, a), sub(p, a)
    d1, d2 = dot(ab, ap), dot(ac, ap)
    if d1 <= 0 and d2 <= 0: return a
    bp = sub(p, b)
    d3, d4 = dot(ab, bp), dot(ac, bp)
    if d3 >= 0 and d4 <= d3: return b
    vc = d1 * d4 - d3 * d2
    if vc <= 0 and d1 >= 0 and d3 <= 0: return axpy(a, d1 / (d1 - d3), ab)
    cp = sub(p, c)
    d5, d6 = dot(ab, cp), dot(ac, cp)
    if d6 >= 0 and d5 <= d6: return c
    vb = d5 * d2 - d1 * d6
    if vb <= 0 and d2 >= 0 and d6 <= 0: return axpy(a, d2 / (d2 - d6), ac)
    va = d3 * d6 - d5 * d4
    if va <= 0 and (d4 - d3) >= 0 and (d5 - d6) >= 0: return axpy(b, (d4 - d3) / ((d4 - d3) + (d5 - d6)), sub(c, b))
    den = 1.0 / (va + vb + vc)
    return axpy(axpy(a, vb * den, ab), vc * den, ac)


CELL = 0.05  # metres: the grid the triangles are binned in; a particle looks at its cell and the 26 around it


def signed_distances(points, verts, tris):
    """Per point: the signed distance to the closest triangle within CELL (None beyond), and that triangle's normal."""
    grid = {}
    normals = []
    for t, (i, j, k) in enumerate(tris):
        a, b, c = verts[i], verts[j], verts[k]
        n = cross(sub(b, a), sub(c, a))
        l = math.sqrt(dot(n, n)) or 1.0
        normals.append((n[0] / l, n[1] / l, n[2] / l))
        lo = [math.floor(min(a[d], b[d], c[d]) / CELL) for d in range(3)]
        hi = [math.floor(max(a[d], b[d], c[d]) / CELL) for d in range(3)]
        for x in range(lo[0], hi[0] + 1):
            for y in range(lo[1], hi[1] + 1):
                for z in range(lo[2], hi[2] + 1):
                    grid.setdefault((x, y, z), []).append(t)
    out = []
    for p in points:
        c0 = [math.floor(p[d] / CELL) for d in range(3)]
        seen, best = set(), (math.inf, None, None)
        for dx in (-1, 0, 1):
            for dy in (-1, 0, 1):
                for dz in (-1, 0, 1):
                    for t in grid.get((c0[0] + dx, c0[1] + dy, c0[2] + dz), ()):
                        if t in seen: continue
                        seen.add(t)
                        i, j, k = tris[t]
                        q = closest_on_triangle(p, verts[i], verts[j], verts[k])
                        d = math.sqrt(dot(sub(p, q), sub(p, q)))
                        if d < best[0]: best = (d, q, t)
        if best[1] is None:
            out.append((None, None))
            continue
        s = 1.0 if dot(sub(p, best[1]), normals[best[2]]) >= 0 else -1.0
        out.append((s * best[0], normals[best[2]]))
    return out


def read_controls(path):
    data = open(path, "rb").read()
    count = struct.unpack_from("<Q", data, 8)[0]
    return struct.unpack_from(f"<{count}d", data, 20)


def main():
    keyframe, out, runs = sys.argv[1], sys.argv[2], [a.split("=", 1) for a in sys.argv[3:]]
    rows = []
    for label, run in runs:
        subprocess.run([keyframe, "export", run, "--format", "obj"], check=True, capture_output=True)
        scene = json.load(open(os.path.join(run, "scene.json")))
        frames = scene["time"]["frames"]
        controls = os.path.join(run, "controls.bin")
        z = read_controls(controls) if os.path.exists(controls) else None
        for frame in range(frames + 1):
            path = os.path.join(run, "export", f"frame_{frame:04d}.obj")
            v, groups = read_obj(path)
            if "cloth" not in groups or "body" not in groups:
                raise SystemExit(f"{path}: no cloth or body group")
            cloth_ids = sorted({i for tri in groups["cloth"] for i in tri})  # the particles, in order
            x = [v[i] for i in cloth_ids]
            bv, bt = v, groups["body"]
            sd = signed_distances(x, bv, bt)
            near = [(d, i) for i, (d, _) in enumerate(sd) if d is not None]
            row = {"run": label, "frame": frame}
            if near:
                d, i = min(near)
                row.update({"min_signed_distance_m": round(d, 5), "particle": i,
                            "particles_inside": sum(1 for d, _ in near if d < 0)})
                # The force over the frame that ends here (block f-1 acts from frame f-1 to f), along the inward normal.
                if z is not None and frame >= 1 and len(z) == frames * 3 * len(x):
                    o = (frame - 1) * 3 * len(x) + 3 * i
                    u = z[o:o + 3]
                    row["control_force_inward_N"] = round(-dot(u, sd[i][1]), 5)
                    row["control_force_N"] = round(math.sqrt(dot(u, u)), 5)
                # Lattice forces (per_frame_lattice, the last frames): the largest node force over the frame, the
                # force each particle at that node gets (the lattice is spread bilinearly, not shared out).
                elif z is not None and len(z) % 27 == 0 and frame > frames - len(z) // 27:
                    o = (frame - 1 - (frames - len(z) // 27)) * 27
                    nodes = [z[o + 3 * k:o + 3 * k + 3] for k in range(9)]
                    u = max(nodes, key=lambda f: dot(f, f))
                    row["lattice_max_node_N"] = round(math.sqrt(dot(u, u)), 5)
                    row["lattice_max_node_up_N"] = round(u[1], 5)
            rows.append(row)
    fields = ["run", "frame", "min_signed_distance_m", "particle", "particles_inside", "control_force_inward_N",
              "control_force_N", "lattice_max_node_N", "lattice_max_node_up_N"]
    with open(out, "w") as f:
        f.write(",".join(fields) + "\n")
        for r in rows:
            f.write(",".join(str(r.get(k, "")) for k in fields) + "\n")


if __name__ == "__main__":
    main()
