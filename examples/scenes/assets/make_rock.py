"""Writes rock.obj: a closed, outward-oriented triangle surface of a lumpy rock about 0.7 m
long, 0.55 m wide and 0.4 m tall (z up, its centre at the origin), an icosphere subdivided three
times (642 vertices, 1280 triangles) pushed out radially by a few smooth bumps and dents. Plain
Python, no packages.

    python3 examples/scenes/assets/make_rock.py
"""

import math
from pathlib import Path

from icosphere import icosphere

# (direction, height as a fraction of the radius, angular width in rad)
BUMPS = [
    ((0.6, 0.3, 0.75), 0.30, 0.50),  # a knob on the top, off centre
    ((-0.7, -0.2, 0.4), 0.20, 0.60),  # a shoulder
    ((0.1, -0.9, 0.2), -0.12, 0.45),  # a dent in one side
    ((-0.2, 0.8, -0.1), 0.15, 0.55),  # a bulge on the other
]
RADIUS = 0.27
SCALE = (1.3, 1.0, 0.75)  # longer along x, squatter along z


def unit(v):
    n = math.sqrt(sum(x * x for x in v))
    return tuple(x / n for x in v)


def radius(u):
    r = RADIUS
    for d, height, width in BUMPS:
        d = unit(d)
        angle = math.acos(max(-1.0, min(1.0, sum(a * b for a, b in zip(u, d)))))
        r *= 1.0 + height * math.exp(-((angle / width) ** 2))
    return r


def main():
    units, faces = icosphere(3)
    points = [tuple(radius(u) * x * s for x, s in zip(u, SCALE)) for u in units]
    out = Path(__file__).with_name("rock.obj")
    with out.open("w") as f:
        f.write("# rock.obj: a lumpy rock for examples/scenes, written by make_rock.py (CC0-1.0)\n")
        for x in points:
            f.write(f"v {x[0]:.6f} {x[1]:.6f} {x[2]:.6f}\n")
        for a, b, c in faces:
            f.write(f"f {a + 1} {b + 1} {c + 1}\n")
    lo = [min(p[i] for p in points) for i in range(3)]
    hi = [max(p[i] for p in points) for i in range(3)]
    print(f"{out}: {len(points)} vertices, {len(faces)} triangles, extent {lo} to {hi}")


if __name__ == "__main__":
    main()
