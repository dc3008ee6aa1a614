"""Peer benchmark: NVIDIA Newton's XPBD solver (warp on CPU) on the benchmark cloth.

The same cloth as anim_pbd::scenes::benchmark_cloth with dihedral bending: n x n particles of
1 kg on a 1 m square in the plane z = 0 (Newton is z-up), triangulated with the diagonal
(ix, iy)-(ix+1, iy+1), pinned at the two corners of one edge (mass 0), a distance constraint
("spring", ke = 1e5, so compliance 1e-5) on every triangle edge and a dihedral bending
constraint (edge_ke = 50) on every interior edge, dt = 1/60, `--iterations` XPBD iterations.
Newton's XPBD is Jacobi: every constraint's correction is added to a delta buffer with atomic
adds and applied after each constraint kind, without averaging. Warp runs CPU kernels on one
thread. Prints one JSON line per run (see pypbd_cloth.py), with "diverged" true when the
cloth left a 100 m box or produced NaN.
"""

import argparse
import json
import time

import numpy as np
import warp as wp

import newton


def build(n):
    b = newton.ModelBuilder()
    h = 1.0 / (n - 1)
    idx = lambda ix, iy: iy * n + ix
    for iy in range(n):
        for ix in range(n):
            pinned = iy == 0 and (ix == 0 or ix == n - 1)
            b.add_particle(wp.vec3(ix * h, iy * h, 0.0), wp.vec3(0.0, 0.0, 0.0), 0.0 if pinned else 1.0, radius=0.0)
    tris = []
    for iy in range(n - 1):
        for ix in range(n - 1):
            a = idx(ix, iy)
            bb, d, e = a + 1, a + n, a + n + 1
            tris.append((a, bb, e))
            tris.append((a, e, d))
    uses = {}
    order = []
    for t in tris:
        for k in range(3):
            p, q, r = t[k], t[(k + 1) % 3], t[(k + 2) % 3]
            key = (min(p, q), max(p, q))
            if key not in uses:
                uses[key] = []
                order.append(key)
            uses[key].append((p, q, r))
    for (p, q) in order:
        b.add_spring(p, q, 1e5, 0.0, 0.0)
    edges = 0
    for key in order:
        u = uses[key]
        if len(u) == 2:
            (e0, e1, o0), o1 = u[0], u[1][2]
            b.add_edge(o0, o1, e0, e1, edge_ke=50.0, edge_kd=0.0)
            edges += 1
    model = b.finalize(device="cpu")
    return model, len(order) + edges


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--n", type=int, default=50)
    ap.add_argument("--iterations", type=int, default=5)
    ap.add_argument("--steps", type=int, default=20)
    ap.add_argument("--repeats", type=int, default=5)
    a = ap.parse_args()
    wp.config.quiet = True
    wp.init()
    with wp.ScopedDevice("cpu"):
        model, constraints = build(a.n)
        solver = newton.solvers.SolverXPBD(model, iterations=a.iterations)
        times = []
        diverged = False
        min_z = float("nan")
        for rep in range(a.repeats + 1):
            s0, s1 = model.state(), model.state()
            control = model.control()
            dt = 1.0 / 60.0
            solver.step(s0, s1, control, None, dt)  # warm up (compiles kernels)
            s0, s1 = s1, s0
            wp.synchronize()
            t = time.perf_counter()
            for _ in range(a.steps):
                solver.step(s0, s1, control, None, dt)
                s0, s1 = s1, s0
            wp.synchronize()
            if rep > 0:
                times.append((time.perf_counter() - t) / a.steps)
            q = s0.particle_q.numpy()
            min_z = float(np.min(q[:, 2]))
            if not np.all(np.isfinite(q)) or np.max(np.abs(q)) > 100.0:
                diverged = True
        times.sort()
        print(json.dumps({
            "code": "newton-xpbd",
            "version": newton.__version__ + " / warp " + wp.__version__,
            "n": a.n,
            "iterations": a.iterations,
            "constraints": constraints,
            "per_step_s": times[len(times) // 2],
            "min_height": min_z,
            "threads": 1,
            "diverged": diverged,
        }))


if __name__ == "__main__":
    main()
