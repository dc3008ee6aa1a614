"""Taichi (CPU) peer of anim-springs' benchmark cloth, for `cargo xtask bench --peers`.

Builds the same n x n cloth as `anim_springs::scenes::benchmark_cloth` (1 m square at height
1 m, total mass 1 kg, structural / shear / bending springs of stiffness 1000 / 500 / 200 N/m,
damping 0.001 N s/m along every spring, gravity -9.81 z, corners (0, 0) and (n-1, 0) pinned), in
float64, and times symplectic Euler steps of dt = 2e-5 s:

    f = m g + sum_springs [-k (L - l) n - c ((v_i - v_j) . n) n],  v += dt f / m,  x += dt v.

Two force kernels are timed:
  * "list": one parallel loop over an explicit spring list with atomic adds into the particle
    forces (a general network, like anim-springs' data structure);
  * "stencil": one parallel loop over particles visiting the 12 grid neighbours at fixed offsets
    (no index arrays, each spring computed twice), the structure of Taichi's own cloth examples.

Prints one JSON object per variant on stdout: per-step seconds (median of repeats), and
checksums of the final positions (sum of z, min z) so the caller can check both codes computed
the same motion.
"""

import argparse
import json
import statistics
import sys
import time

import taichi as ti


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--n", type=int, default=128)
    ap.add_argument("--steps", type=int, default=200)
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--dt", type=float, default=2e-5)
    args = ap.parse_args()

    ti.init(arch=ti.cpu, cpu_max_num_threads=args.threads, default_fp=ti.f64, log_level=ti.ERROR)

    n = args.n
    np_ = n * n
    dt = args.dt
    mass = 1.0 / np_
    size = 1.0
    k_struct, k_shear, k_bend, damping = 1000.0, 500.0, 200.0, 0.001

    x = ti.Vector.field(3, ti.f64, shape=np_)
    v = ti.Vector.field(3, ti.f64, shape=np_)
    f = ti.Vector.field(3, ti.f64, shape=np_)
    pinned = ti.field(ti.i32, shape=np_)

    # Spring list, in the same order as the Rust builder.
    springs = []
    idx = lambda ix, iy: iy * n + ix
    for iy in range(n):
        for ix in range(n):
            if ix + 1 < n:
                springs.append((idx(ix, iy), idx(ix + 1, iy), k_struct))
            if iy + 1 < n:
                springs.append((idx(ix, iy), idx(ix, iy + 1), k_struct))
    for iy in range(n - 1):
        for ix in range(n - 1):
            springs.append((idx(ix, iy), idx(ix + 1, iy + 1), k_shear))
            springs.append((idx(ix + 1, iy), idx(ix, iy + 1), k_shear))
    for iy in range(n):
        for ix in range(n):
            if ix + 2 < n:
                springs.append((idx(ix, iy), idx(ix + 2, iy), k_bend))
            if iy + 2 < n:
                springs.append((idx(ix, iy), idx(ix, iy + 2), k_bend))
    ns = len(springs)
    s_ends = ti.Vector.field(2, ti.i32, shape=ns)
    s_rest = ti.field(ti.f64, shape=ns)
    s_k = ti.field(ti.f64, shape=ns)

    h = size / (n - 1)

    @ti.kernel
    def init_particles():
        for p in range(np_):
            ix = p % n
            iy = p // n
            x[p] = ti.Vector([ix * h, iy * h, 1.0])
            v[p] = ti.Vector([0.0, 0.0, 0.0])
            pinned[p] = 0
        pinned[0] = 1
        pinned[n - 1] = 1

    import numpy as np

    ends = np.array([(a, b) for a, b, _ in springs], dtype=np.int32)
    ks = np.array([k for _, _, k in springs], dtype=np.float64)
    s_ends.from_numpy(ends)
    s_k.from_numpy(ks)

    @ti.kernel
    def init_rest():
        for s in range(ns):
            a = s_ends[s][0]
            b = s_ends[s][1]
            s_rest[s] = (x[a] - x[b]).norm()

    gravity = ti.Vector([0.0, 0.0, -9.81])

    @ti.kernel
    def step_list():
        for p in range(np_):
            f[p] = mass * gravity
        for s in range(ns):
            a = s_ends[s][0]
            b = s_ends[s][1]
            d = x[a] - x[b]
            length = d.norm()
            nrm = d / length
            fs = -(s_k[s] * (length - s_rest[s]) + damping * nrm.dot(v[a] - v[b])) * nrm
            ti.atomic_add(f[a], fs)
            ti.atomic_add(f[b], -fs)
        for p in range(np_):
            if pinned[p] == 0:
                v[p] += dt * f[p] / mass
                x[p] += dt * v[p]

    offsets = ti.Vector.field(2, ti.i32, shape=12)
    offset_k = ti.field(ti.f64, shape=12)
    offset_rest = ti.field(ti.f64, shape=12)
    offs = [(1, 0), (-1, 0), (0, 1), (0, -1), (1, 1), (-1, -1), (1, -1), (-1, 1), (2, 0), (-2, 0), (0, 2), (0, -2)]
    kofs = [k_struct] * 4 + [k_shear] * 4 + [k_bend] * 4
    offsets.from_numpy(np.array(offs, dtype=np.int32))
    offset_k.from_numpy(np.array(kofs, dtype=np.float64))
    offset_rest.from_numpy(np.array([h * (a * a + b * b) ** 0.5 for a, b in offs], dtype=np.float64))

    @ti.kernel
    def step_stencil():
        for p in range(np_):
            ix = p % n
            iy = p // n
            acc = mass * gravity
            for o in range(12):
                jx = ix + offsets[o][0]
                jy = iy + offsets[o][1]
                if 0 <= jx < n and 0 <= jy < n:
                    q = jy * n + jx
                    d = x[p] - x[q]
                    length = d.norm()
                    nrm = d / length
                    acc += -(offset_k[o] * (length - offset_rest[o]) + damping * nrm.dot(v[p] - v[q])) * nrm
            f[p] = acc
        for p in range(np_):
            if pinned[p] == 0:
                v[p] += dt * f[p] / mass
                x[p] += dt * v[p]

    for name, step in (("list", step_list), ("stencil", step_stencil)):
        times = []
        for rep in range(args.repeats + 1):
            init_particles()
            init_rest()
            step()  # compile (first repeat) and warm up
            init_particles()
            ti.sync()
            t0 = time.perf_counter()
            for _ in range(args.steps):
                step()
            ti.sync()
            if rep > 0:
                times.append((time.perf_counter() - t0) / args.steps)
        xs = x.to_numpy()
        print(
            json.dumps(
                {
                    "variant": name,
                    "n": n,
                    "springs": ns,
                    "threads": args.threads,
                    "steps": args.steps,
                    "per_step_s": statistics.median(times),
                    "sum_z": float(xs[:, 2].sum()),
                    "min_z": float(xs[:, 2].min()),
                    "taichi": ".".join(str(c) for c in ti.__version__),
                }
            )
        )
        sys.stdout.flush()


if __name__ == "__main__":
    main()
