#!/usr/bin/env python3
"""Writes water-blob.obj: a lumpy closed blob of unit size, for examples/scenes/water-blob.toml.

An icosahedron subdivided three times onto the unit sphere (642 vertices, 1280 triangles), each
vertex pushed out along its direction by a few smooth lobes: a star-shaped, closed, manifold
surface with triangles counter-clockwise seen from outside. Coordinates are y up, about the
origin, radius 0.8 to 1.1. Deterministic (no random numbers).

    python3 examples/scenes/assets/make_water_blob.py

The output is dedicated to the public domain (CC0-1.0).
"""
import math
from pathlib import Path


def icosphere(levels):
    t = (1.0 + math.sqrt(5.0)) / 2.0
    verts = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t),
             (0, -1, -t), (0, 1, -t), (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
    verts = [unit(v) for v in verts]
    faces = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4),
             (11, 10, 2), (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8),
             (3, 8, 9), (4, 9, 5), (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    for _ in range(levels):
        midpoints = {}

        def middle(a, b):
            key = (min(a, b), max(a, b))
            if key not in midpoints:
                va, vb = verts[a], verts[b]
                verts.append(unit(tuple((x + y) / 2.0 for x, y in zip(va, vb))))
                midpoints[key] = len(verts) - 1
            return midpoints[key]

        refined = []
        for a, b, c in faces:
            ab, bc, ca = middle(a, b), middle(b, c), middle(c, a)
            refined += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
        faces = refined
    return verts, faces


def unit(v):
    n = math.sqrt(sum(x * x for x in v))
    return tuple(x / n for x in v)


def radius(d):
    x, y, z = d
    return 1.0 + 0.12 * math.sin(3.0 * x + 0.5) * math.cos(2.0 * y) + 0.08 * math.cos(4.0 * z - 1.0 * x)


def main():
    verts, faces = icosphere(3)
    out = Path(__file__).with_name("water-blob.obj")
    lines = ["# water-blob.obj: a lumpy closed blob, y up, radius 0.8 to 1.1 (make_water_blob.py)",
             "# CC0-1.0: dedicated to the public domain"]
    for d in verts:
        r = radius(d)
        lines.append("v {:.6f} {:.6f} {:.6f}".format(*(r * x for x in d)))
    for a, b, c in faces:
        lines.append(f"f {a + 1} {b + 1} {c + 1}")
    out.write_text("\n".join(lines) + "\n")
    print(f"wrote {out} ({len(verts)} vertices, {len(faces)} triangles)")


if __name__ == "__main__":
    main()
