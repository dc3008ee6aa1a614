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

from icosphere import icosphere


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
