"""Writes cloth.obj: a flat square cloth, 1 m on a side, in the plane z = 0 centred on the
origin, as a grid of 41 x 41 vertices (2.5 cm apart) and 3200 triangles, each square split
along alternating diagonals so the cloth folds the same way in every direction.

Vertex (ix, iy) is line ix + 41 iy of the vertex list (0-based), at x = -0.5 + ix / 40 and
y = -0.5 + iy / 40: vertices 0 and 40 are the corners at y = -0.5, 1640 and 1680 those at
y = 0.5.

    python3 examples/scenes/assets/make_cloth.py
"""

from pathlib import Path

N = 41
SIDE = 1.0

lines = [f"# {N} x {N} square cloth, {SIDE} m side, written by make_cloth.py (CC0-1.0)"]
for iy in range(N):
    for ix in range(N):
        x = -SIDE / 2 + SIDE * ix / (N - 1)
        y = -SIDE / 2 + SIDE * iy / (N - 1)
        lines.append(f"v {x:.6f} {y:.6f} 0")
for iy in range(N - 1):
    for ix in range(N - 1):
        # OBJ indices are 1-based.
        a = iy * N + ix + 1
        b, d, e = a + 1, a + N, a + N + 1
        if (ix + iy) % 2 == 0:
            lines += [f"f {a} {b} {e}", f"f {a} {e} {d}"]
        else:
            lines += [f"f {a} {b} {d}", f"f {b} {e} {d}"]
Path(__file__).with_name("cloth.obj").write_text("\n".join(lines) + "\n")
