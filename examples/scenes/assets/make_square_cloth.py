"""Writes square-cloth.obj: a flat square cloth, 1.2 m on a side, centred on the origin in the
plane z = 0, as a grid of 41 x 41 vertices (3 cm apart) whose square cells are split into two
triangles along alternating diagonals, so the cloth has no preferred shear direction.
Vertex (i, j) is OBJ vertex j * 41 + i + 1 (0-based index j * 41 + i): x grows with i, y with j.

    python3 examples/scenes/assets/make_square_cloth.py
"""

from pathlib import Path

N = 41  # vertices per side
SIZE = 1.2  # m

lines = [
    "# square-cloth.obj: a 1.2 m square cloth, 41 x 41 vertices, made by make_square_cloth.py (CC0-1.0)"
]
for j in range(N):
    for i in range(N):
        x = -SIZE / 2 + SIZE * i / (N - 1)
        y = -SIZE / 2 + SIZE * j / (N - 1)
        lines.append(f"v {x:.6f} {y:.6f} 0")
for j in range(N - 1):
    for i in range(N - 1):
        a = j * N + i + 1  # 1-based corners of the cell: a, b along x, c, d one row up
        b, c, d = a + 1, a + N, a + N + 1
        if (i + j) % 2 == 0:
            lines += [f"f {a} {b} {d}", f"f {a} {d} {c}"]
        else:
            lines += [f"f {a} {b} {c}", f"f {b} {d} {c}"]
Path(__file__).with_name("square-cloth.obj").write_text("\n".join(lines) + "\n")
