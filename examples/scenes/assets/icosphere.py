"""The icosphere the blob scripts start from: the icosahedron on the unit sphere, each triangle
split in four `levels` times with the edge midpoints pushed out onto the sphere (shared by the
edge's two triangles), triangles counter-clockwise seen from outside. Plain Python, no packages.
"""

import math


def unit(v):
    n = math.sqrt(sum(x * x for x in v))
    return tuple(x / n for x in v)


def icosphere(levels):
    """Returns (vertices, faces): unit vectors as tuples and 0-based vertex triples."""
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
