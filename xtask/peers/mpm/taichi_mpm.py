"""Taichi's MLS-MPM fluid (the `mpm88` / `mpm3d` examples) on the CPU backend, timed per substep.

The scene is the one of `anim_mpm::scenes::benchmark_2d` / `benchmark_3d`: `n` cells per axis,
dt = 2e-4 * 128 / n (2D) or 4e-4 * 32 / n (3D), E = 400 (tau = E (J - 1) I), unit density,
particle volume (h/2)^2, gravity 9.8, walls 3 nodes thick, n^2/2 (2D) or n^3/4 (3D) particles
uniformly random in [0.2, 0.6]^2 / [0.15, 0.55]^3. The kernels are Taichi's examples
(python/taichi/examples/simulation/mpm88.py and mpm3d.py) with the dimension as a parameter.

Usage: python taichi_mpm.py --dim 2 --n 128 --steps 200 --repeats 5 --threads 1
Prints one JSON line: {"taichi": ..., "dim": ..., "n": ..., "particles": ..., "threads": ...,
"per_step_s": ..., "mean_y": ...}. mean_y (mean particle height after the warm-up and the timed
steps) is a sanity value: the random initial positions differ from ours, so it agrees only
statistically.
"""

import argparse
import json
import time

import numpy as np
import taichi as ti

ap = argparse.ArgumentParser()
ap.add_argument("--dim", type=int, default=2)
ap.add_argument("--n", type=int, default=128)
ap.add_argument("--steps", type=int, default=200)
ap.add_argument("--repeats", type=int, default=5)
ap.add_argument("--threads", type=int, default=1)
ap.add_argument("--warmup", type=int, default=50)
args = ap.parse_args()

ti.init(arch=ti.cpu, cpu_max_num_threads=args.threads, default_fp=ti.f32, random_seed=1)

dim, n_grid = args.dim, args.n
if dim == 2:
    n_particles = n_grid * n_grid // 2
    dt = 2e-4 * 128 / n_grid
    lo, side = 0.2, 0.4
else:
    n_particles = n_grid ** 3 // 4
    dt = 4e-4 * 32 / n_grid
    lo, side = 0.15, 0.4
dx = 1 / n_grid
p_rho = 1
p_vol = (dx * 0.5) ** 2
p_mass = p_vol * p_rho
gravity = 9.8
bound = 3
E = 400

x = ti.Vector.field(dim, float, n_particles)
v = ti.Vector.field(dim, float, n_particles)
C = ti.Matrix.field(dim, dim, float, n_particles)
J = ti.field(float, n_particles)
grid_v = ti.Vector.field(dim, float, (n_grid,) * dim)
grid_m = ti.field(float, (n_grid,) * dim)
neighbour = (3,) * dim


@ti.kernel
def substep():
    for I in ti.grouped(grid_m):
        grid_v[I] = ti.zero(grid_v[I])
        grid_m[I] = 0
    ti.loop_config(block_dim=n_grid)
    for p in x:
        Xp = x[p] / dx
        base = int(Xp - 0.5)
        fx = Xp - base
        w = [0.5 * (1.5 - fx) ** 2, 0.75 - (fx - 1) ** 2, 0.5 * (fx - 0.5) ** 2]
        stress = -dt * 4 * E * p_vol * (J[p] - 1) / dx**2
        affine = ti.Matrix.identity(float, dim) * stress + p_mass * C[p]
        for offset in ti.static(ti.grouped(ti.ndrange(*neighbour))):
            dpos = (offset - fx) * dx
            weight = 1.0
            for i in ti.static(range(dim)):
                weight *= w[offset[i]][i]
            grid_v[base + offset] += weight * (p_mass * v[p] + affine @ dpos)
            grid_m[base + offset] += weight * p_mass
    for I in ti.grouped(grid_m):
        if grid_m[I] > 0:
            grid_v[I] /= grid_m[I]
        grid_v[I][1] -= dt * gravity
        cond = (I < bound) & (grid_v[I] < 0) | (I > n_grid - bound) & (grid_v[I] > 0)
        grid_v[I] = ti.select(cond, 0, grid_v[I])
    ti.loop_config(block_dim=n_grid)
    for p in x:
        Xp = x[p] / dx
        base = int(Xp - 0.5)
        fx = Xp - base
        w = [0.5 * (1.5 - fx) ** 2, 0.75 - (fx - 1) ** 2, 0.5 * (fx - 0.5) ** 2]
        new_v = ti.zero(v[p])
        new_C = ti.zero(C[p])
        for offset in ti.static(ti.grouped(ti.ndrange(*neighbour))):
            dpos = (offset - fx) * dx
            weight = 1.0
            for i in ti.static(range(dim)):
                weight *= w[offset[i]][i]
            g_v = grid_v[base + offset]
            new_v += weight * g_v
            new_C += 4 * weight * g_v.outer_product(dpos) / dx**2
        v[p] = new_v
        x[p] += dt * v[p]
        J[p] *= 1 + dt * new_C.trace()
        C[p] = new_C


@ti.kernel
def init():
    for i in range(n_particles):
        x[i] = ti.Vector([ti.random() for _ in range(dim)]) * side + lo
        J[i] = 1


init()
for _ in range(args.warmup):
    substep()
ti.sync()
times = []
for _ in range(args.repeats):
    t0 = time.perf_counter()
    for _ in range(args.steps):
        substep()
    ti.sync()
    times.append((time.perf_counter() - t0) / args.steps)
times.sort()
mean_y = float(np.mean(x.to_numpy()[:, 1]))
print(
    json.dumps(
        {
            "taichi": ".".join(map(str, ti.__version__)),
            "dim": dim,
            "n": n_grid,
            "particles": n_particles,
            "threads": args.threads,
            "per_step_s": times[len(times) // 2],
            "mean_y": mean_y,
        }
    )
)
