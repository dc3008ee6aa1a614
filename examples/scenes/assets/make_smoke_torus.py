"""Writes smoke-torus.obj: a closed torus surface (major radius 1, minor radius 0.4, axis y,
centred on the origin), 48 segments around the axis by 20 around the tube, 1920 triangles facing
outward. Plain Python, no packages needed.

    python3 examples/scenes/assets/make_smoke_torus.py
"""

import math
from pathlib import Path

MAJOR, MINOR, AROUND, TUBE = 1.0, 0.4, 48, 20


def vertex(i, j):
    u = 2 * math.pi * i / AROUND
    v = 2 * math.pi * j / TUBE
    ring = MAJOR + MINOR * math.cos(v)
    return (ring * math.cos(u), MINOR * math.sin(v), ring * math.sin(u))


def index(i, j):
    return (i % AROUND) * TUBE + (j % TUBE)


vertices = [vertex(i, j) for i in range(AROUND) for j in range(TUBE)]
triangles = []
for i in range(AROUND):
    for j in range(TUBE):
        a, b = index(i, j), index(i + 1, j)
        c, d = index(i + 1, j + 1), index(i, j + 1)
        triangles += [(a, d, c), (a, c, b)]

# Outward: the enclosed volume by the divergence theorem is positive.
volume = sum(
    (lambda p, q, r: p[0] * (q[1] * r[2] - q[2] * r[1]) - p[1] * (q[0] * r[2] - q[2] * r[0])
     + p[2] * (q[0] * r[1] - q[1] * r[0]))(*(vertices[k] for k in t)) / 6.0
    for t in triangles
)
if volume < 0:
    triangles = [(a, c, b) for (a, b, c) in triangles]
    volume = -volume
assert abs(volume - 2 * math.pi**2 * MAJOR * MINOR**2) < 0.02 * volume

lines = [
    "# smoke-torus.obj: a closed torus surface, major radius 1, minor radius 0.4, axis y,",
    "# made by make_smoke_torus.py. CC0-1.0.",
]
lines += ["v %.6f %.6f %.6f" % p for p in vertices]
lines += ["f %d %d %d" % tuple(k + 1 for k in t) for t in triangles]
Path(__file__).with_name("smoke-torus.obj").write_text("\n".join(lines) + "\n")
