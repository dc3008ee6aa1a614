"""Writes blob.obj: a closed, outward-oriented triangle surface of a soft blob 0.35 m
long (a round body with a smaller head bump and a tail bump), an icosphere subdivided three
times (642 vertices, 1280 triangles) pushed out radially. Needs numpy only.

    python3 examples/scenes/assets/make_blob.py
"""

from pathlib import Path

import numpy as np
from icosphere import icosphere


def radius(u):
    """The blob's radius along the unit directions u (rows): a squashed ball with two bumps."""
    bumps = [
        # (direction, height as a fraction of the radius, angular width)
        ((0.75, 0.0, 0.66), 0.45, 0.45),  # the head, up and forward
        ((-0.9, 0.0, 0.43), 0.25, 0.35),  # the tail
    ]
    r = 0.12 * np.ones(len(u))
    for d, height, width in bumps:
        d = np.array(d) / np.linalg.norm(d)
        angle = np.arccos(np.clip(u @ d, -1.0, 1.0))
        r *= 1.0 + height * np.exp(-((angle / width) ** 2))
    # Flatter underneath, longer along x.
    scale = np.array([1.25, 1.0, 0.85])
    return r, scale


def main():
    u, faces = icosphere(3)
    u = np.array(u)
    r, scale = radius(u)
    p = u * r[:, None] * scale
    out = Path(__file__).with_name("blob.obj")
    with out.open("w") as f:
        f.write("# blob.obj: a soft blob for examples/scenes, written by make_blob.py (CC0-1.0)\n")
        for x in p:
            f.write(f"v {x[0]:.6f} {x[1]:.6f} {x[2]:.6f}\n")
        for a, b, c in faces:
            f.write(f"f {a + 1} {b + 1} {c + 1}\n")
    print(f"{out}: {len(p)} vertices, {len(faces)} triangles, extent {p.min(0)} to {p.max(0)}")


if __name__ == "__main__":
    main()
