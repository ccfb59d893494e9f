#!/usr/bin/env python3
"""Writes the cloth meshes of the mesh scenes (cloth.mesh) under assets/cloth/:

  tablecloth.obj   a round tablecloth: a disc of radius 0.6 m in rings of triangles, Y up, centred on the origin
  swallowtail.obj  a 1.2 m x 0.72 m flag of 20 x 12 vertices (quads) with a V cut 0.3 m deep into its fly end,
                   in the x-y plane, hoist edge on x = 0
  poncho.obj       a 0.8 m x 1.0 m poncho (x across the shoulders, z front to back) of 0.05 m quads, lying flat
                   in the x-z plane (Y up) centred on the origin, with a neck hole: the quads whose centre lies
                   within 0.12 m of the origin are left out

Usage: scripts/make_cloth_meshes.py [out-dir]   (default assets/cloth)
"""
import math
import os
import sys


def write_obj(path, name, vertices, faces):
    with open(path, "w") as f:
        f.write(f"# {name}: written by scripts/make_cloth_meshes.py\no {name}\n")
        for v in vertices:
            f.write("v %.6f %.6f %.6f\n" % v)
        for face in faces:
            f.write("f " + " ".join(str(i + 1) for i in face) + "\n")


def tablecloth(radius=0.6, rings=10):
    """Ring k holds 6k vertices; the triangles between two rings wind counter-clockwise seen from +Y."""
    vertices = [(0.0, 0.0, 0.0)]
    start = [0]
    for k in range(1, rings + 1):
        start.append(len(vertices))
        r = radius * k / rings
        for j in range(6 * k):
            a = 2 * math.pi * j / (6 * k)
            vertices.append((r * math.cos(a), 0.0, -r * math.sin(a)))
    faces = []
    for k in range(1, rings + 1):
        inner_n = 1 if k == 1 else 6 * (k - 1)
        outer_n = 6 * k
        i = o = 0
        # March round both rings, always advancing the one whose next vertex lies at the smaller angle.
        while o < outer_n or (k > 1 and i < inner_n):
            a_in = (i + 1) / inner_n if k > 1 else 2.0
            a_out = (o + 1) / outer_n
            vi = start[k - 1] + (i % inner_n)
            vo = start[k] + (o % outer_n)
            if o < outer_n and (a_out <= a_in or i >= inner_n):
                faces.append((vi, vo, start[k] + ((o + 1) % outer_n)))
                o += 1
            else:
                faces.append((vi, vo, start[k - 1] + ((i + 1) % inner_n)))
                i += 1
    return vertices, faces


def swallowtail(nx=20, ny=12, width=1.2, height=0.72, cut=0.3):
    dx, dy = width / (nx - 1), height / (ny - 1)
    def in_cut(x, y):
        return x > width - cut and abs(y - height / 2) < (x - (width - cut)) * (height / 2) / cut
    faces, used = [], set()
    for j in range(ny - 1):
        for i in range(nx - 1):
            cx, cy = (i + 0.5) * dx, (j + 0.5) * dy
            if in_cut(cx, cy):
                continue
            q = (j * nx + i, j * nx + i + 1, (j + 1) * nx + i + 1, (j + 1) * nx + i)
            faces.append(q)
            used.update(q)
    index, vertices = {}, []
    for j in range(ny):
        for i in range(nx):
            if j * nx + i in used:
                index[j * nx + i] = len(vertices)
                vertices.append((i * dx, j * dy, 0.0))
    return vertices, [tuple(index[v] for v in f) for f in faces]


def poncho(width=0.8, length=1.0, spacing=0.05, hole=0.12):
    nx, nz = round(width / spacing) + 1, round(length / spacing) + 1
    x0, z0 = -width / 2, -length / 2
    faces, used = [], set()
    for k in range(nz - 1):
        for i in range(nx - 1):
            cx, cz = x0 + (i + 0.5) * spacing, z0 + (k + 0.5) * spacing
            if math.hypot(cx, cz) < hole:
                continue
            # (x, z) -> (x, z + dz) -> (x + dx, z + dz): counter-clockwise seen from +Y (the normal points up).
            q = (k * nx + i, (k + 1) * nx + i, (k + 1) * nx + i + 1, k * nx + i + 1)
            faces.append(q)
            used.update(q)
    index, vertices = {}, []
    for k in range(nz):
        for i in range(nx):
            if k * nx + i in used:
                index[k * nx + i] = len(vertices)
                vertices.append((x0 + i * spacing, 0.0, z0 + k * spacing))
    return vertices, [tuple(index[v] for v in f) for f in faces]


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..", "assets", "cloth")
    os.makedirs(out, exist_ok=True)
    write_obj(os.path.join(out, "tablecloth.obj"), "Tablecloth", *tablecloth())
    write_obj(os.path.join(out, "swallowtail.obj"), "Swallowtail", *swallowtail())
    write_obj(os.path.join(out, "poncho.obj"), "Poncho", *poncho())


if __name__ == "__main__":
    main()
