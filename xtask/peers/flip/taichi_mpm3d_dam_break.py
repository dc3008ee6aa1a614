"""Taichi's MLS-MPM 3D fluid (the `mpm3d` example) on the CPU backend as a dam break, timed per step.

The peer of `cargo xtask bench --peers --filter flip`. The scene is the one of
`anim_flip::scenes::benchmark_dam_break_3d`: a cube of `n` cells per axis (dx = 1/n m), a block
of n/4 x n/2 x n/2 cells (x, y up, z) in the corner of the fluid region, seeded on the same
lattice (2 particles per cell and axis, 8 per cell, n^3 / 2 particles), at rest, gravity 9.8.
The kernels are Taichi's mpm3d example (python/taichi/examples/simulation/mpm3d.py): a weakly
compressible fluid, stress tau = E (J - 1) I with E = 400 at unit density, explicit time steps of
dt = 4e-4 * 32 / n (1e-4 s at n = 128), walls 3 nodes thick. Only the particle volume differs
from the example: (dx / 2)^3, the volume of one particle at 8 per cell (the example's
(dx / 2)^2 is its 2D value). Single precision, as the example.

Usage: python taichi_mpm3d_dam_break.py --n 128 --steps 5 --repeats 3 --threads 2 --warmup 20
Prints one JSON line: {"taichi": ..., "n": ..., "particles": ..., "threads": ..., "dt": ...,
"per_step_s": ..., "front": ...}; front is the largest x of a particle minus the column's left
edge after the warm-up and the timed steps (a sanity value: the block has collapsed a little).
"""

import argparse
import json
import time

import numpy as np
import taichi as ti

ap = argparse.ArgumentParser()
ap.add_argument("--n", type=int, default=128)
ap.add_argument("--steps", type=int, default=5)
ap.add_argument("--repeats", type=int, default=3)
ap.add_argument("--threads", type=int, default=1)
ap.add_argument("--warmup", type=int, default=20)
args = ap.parse_args()

ti.init(arch=ti.cpu, cpu_max_num_threads=args.threads, default_fp=ti.f32)

dim, n_grid = 3, args.n
assert n_grid % 4 == 0 and n_grid >= 8, "n must be a multiple of 4, at least 8"
dx = 1 / n_grid
dt = 4e-4 * 32 / n_grid
bound = 3
# The block: n/4 x n/2 x n/2 cells from the corner of the fluid region (bound cells in), 2
# particles per cell and axis.
cells = (n_grid // 4, n_grid // 2, n_grid // 2)
lattice = tuple(2 * c for c in cells)
n_particles = lattice[0] * lattice[1] * lattice[2]
lo = bound * dx
p_rho = 1
p_vol = (dx * 0.5) ** 3
p_mass = p_vol * p_rho
gravity = 9.8
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
        k = ti.Vector([i // (lattice[1] * lattice[2]), (i // lattice[2]) % lattice[1], i % lattice[2]])
        x[i] = lo + (k + 0.5) * (dx * 0.5)
        v[i] = ti.zero(v[i])
        C[i] = ti.zero(C[i])
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
front = float(np.max(x.to_numpy()[:, 0]) - lo)
print(
    json.dumps(
        {
            "taichi": ".".join(map(str, ti.__version__)),
            "n": n_grid,
            "particles": n_particles,
            "threads": args.threads,
            "dt": dt,
            "per_step_s": times[len(times) // 2],
            "front": front,
        }
    )
)
