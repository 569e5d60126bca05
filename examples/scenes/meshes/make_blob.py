#!/usr/bin/env python3
"""Writes blob.obj, the mesh of the built-in scene `mesh`: a twice-subdivided icosahedron
(162 vertices, 320 triangles, closed, outward counter-clockwise faces) pushed out radially into a
lumpy, bunny-like blob (a body, a head lobe and two ear lobes). A radial deformation of a sphere
by a positive radius keeps the surface closed and free of self-intersections.

Run: python3 examples/scenes/meshes/make_blob.py (writes next to itself; deterministic)."""
import math
import os

t = (1 + 5 ** 0.5) / 2
verts = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t), (0, -1, -t),
         (0, 1, -t), (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
faces = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4),
         (11, 10, 2), (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8),
         (3, 8, 9), (4, 9, 5), (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)]


def unit(v):
    n = math.sqrt(sum(c * c for c in v))
    return tuple(c / n for c in v)


verts = [unit(v) for v in verts]
for _ in range(2):
    cache = {}

    def mid(a, b):
        key = (min(a, b), max(a, b))
        if key not in cache:
            verts.append(unit(tuple((verts[a][k] + verts[b][k]) / 2 for k in range(3))))
            cache[key] = len(verts) - 1
        return cache[key]

    new = []
    for a, b, c in faces:
        ab, bc, ca = mid(a, b), mid(b, c), mid(c, a)
        new += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
    faces = new


def lobe(d, axis, power):
    a = unit(axis)
    return max(0.0, sum(d[k] * a[k] for k in range(3))) ** power


def radius(d):
    body = 1.0 + 0.08 * math.sin(3 * d[0]) * math.cos(2 * d[2])
    head = 0.35 * lobe(d, (0.7, 0.6, 0.0), 6)
    ears = 0.45 * lobe(d, (0.45, 1.0, 0.25), 24) + 0.45 * lobe(d, (0.45, 1.0, -0.25), 24)
    return 0.7 * (body + head + ears)


centre = (0.0, 0.6, 0.0)
squash = (1.15, 0.8, 0.9)
here = os.path.dirname(os.path.abspath(__file__))
with open(os.path.join(here, "blob.obj"), "w") as f:
    f.write("# blob.obj: made by make_blob.py (a lumpy icosphere; 320 triangles, closed)\n")
    f.write("o blob\n")
    for d in verts:
        r = radius(d)
        p = [centre[k] + squash[k] * r * d[k] for k in range(3)]
        f.write("v %.4f %.4f %.4f\n" % tuple(p))
    for a, b, c in faces:
        f.write("f %d %d %d\n" % (a + 1, b + 1, c + 1))
