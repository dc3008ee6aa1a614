"""Writes jelly-blob.obj: a bunny-like blob, a closed triangle surface about 2 units across (origin at
its centre, z up): an icosphere (three subdivisions, 642 vertices, 1280 triangles) whose radius
along each direction swells into a head, two ears and a tail. Every vertex moves along its own
ray from the centre, so the surface stays closed, manifold and outward oriented.

    python3 examples/scenes/assets/make_jelly_blob.py
"""

from pathlib import Path

import numpy as np
from icosphere import icosphere


def bump(directions, towards, height, width):
    """A smooth swelling of the radius around the unit direction `towards`."""
    towards = np.asarray(towards, dtype=float)
    towards /= np.linalg.norm(towards)
    cos = directions @ towards
    return height * np.exp((cos - 1.0) / width)


def main():
    directions, faces = icosphere(3)
    directions = np.array(directions)
    radius = np.ones(len(directions))
    radius += bump(directions, (0.9, 0.0, 0.6), 0.35, 0.08)  # head, forward (+x) and up
    radius += bump(directions, (0.45, 0.3, 1.0), 0.7, 0.025)  # right ear
    radius += bump(directions, (0.45, -0.3, 1.0), 0.7, 0.025)  # left ear
    radius += bump(directions, (-1.0, 0.0, 0.1), 0.2, 0.03)  # tail
    radius -= bump(directions, (0.0, 0.0, -1.0), 0.25, 0.25)  # a flatter belly
    positions = directions * radius[:, None]
    lines = ["# A bunny-like blob: an icosphere with a head, two ears and a tail (make_jelly_blob.py), CC0-1.0."]
    lines += [f"v {x:.6f} {y:.6f} {z:.6f}" for x, y, z in positions]
    lines += [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in faces]
    Path(__file__).with_name("jelly-blob.obj").write_text("\n".join(lines) + "\n")


main()
