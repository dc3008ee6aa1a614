"""The anim-fem benchmark beam in pbatoolkit (pip `pbatoolkit`): backward Euler steps by a Newton
loop driven from Python on pbatoolkit's stable Neo-Hookean energy, gradient and SPD-projected
Hessian (C++), solved with scipy's sparse direct solve (SuperLU), the way pbatoolkit's examples
drive it.

Same mesh as `anim_fem::scenes::benchmark_beam(cells)`: 1 m x 0.16 m x 0.16 m, cubic cells split
into six Kuhn tetrahedra, E = 1 MPa, nu = 0.45, rho = 1000, clamped at x = 0, gravity -9.81 z,
dt = 0.01 s, lumped mass, Newton stopped when max |dx| <= tol * bounding-box diagonal.

Prints one JSON line: elements, steps, per-step seconds (median over steps 2..), Newton
iterations per step, tip z after the steps.
"""
import argparse
import json
import time

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spl
import pbatoolkit as pbat

fem = pbat.pbat.fem

KUHN = [[0, 1, 3, 7], [0, 1, 5, 7], [0, 2, 3, 7], [0, 2, 6, 7], [0, 4, 5, 7], [0, 4, 6, 7]]


def beam(cells):
    across = int(round(cells * 0.16))
    nx, ny, nz = cells, across, across
    xs = np.linspace(0.0, 1.0, nx + 1)
    ys = np.linspace(-0.08, 0.08, ny + 1)
    zs = np.linspace(0.0, 0.16, nz + 1)
    V = np.array([[x, y, z] for z in zs for y in ys for x in xs])
    idx = lambda i, j, k: i + (nx + 1) * (j + (ny + 1) * k)
    C = []
    for k in range(nz):
        for j in range(ny):
            for i in range(nx):
                corner = lambda c: idx(i + (c & 1), j + ((c >> 1) & 1), k + (c >> 2))
                for t in KUHN:
                    tet = [corner(c) for c in t]
                    p = V[tet]
                    if np.linalg.det(np.array([p[1] - p[0], p[2] - p[0], p[3] - p[0]])) < 0:
                        tet[2], tet[3] = tet[3], tet[2]
                    C.append(tet)
    return V, np.array(C, dtype=np.int64)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--cells", type=int, default=50)
    ap.add_argument("--steps", type=int, default=5)
    ap.add_argument("--tol", type=float, default=1e-6)
    a = ap.parse_args()
    V, C = beam(a.cells)
    element = fem.Element.Tetrahedron
    X, E = fem.mesh(V.T, C.T, element=element, order=1)
    n = X.shape[1]
    wg = fem.mesh_quadrature_weights(E, X, element, order=1, quadrature_order=1).flatten(order="F")
    eg = fem.mesh_quadrature_elements(E.shape[1], 1).flatten(order="F")
    GNeg = fem.shape_function_gradients(E, X, element=element, order=1, dims=3, quadrature_order=1)
    Y, nu, rho = 1e6, 0.45, 1000.0
    mu = Y / (2 * (1 + nu))
    lam = Y * nu / ((1 + nu) * (1 - 2 * nu))
    mug = np.full(wg.shape, mu)
    lamg = np.full(wg.shape, lam)
    # Lumped mass: rho W / 4 per vertex of each element.
    m = np.zeros(n)
    for e in range(E.shape[1]):
        m[E[:, e]] += rho * wg[e] / 4.0
    M = np.repeat(m, 3)
    g = np.zeros(3 * n)
    g[2::3] = -9.81
    fext = M * g
    x = X.flatten(order="F").copy()
    v = np.zeros_like(x)
    fixed = np.repeat(X[0, :] < 1e-9, 3)
    free = ~fixed
    dt = 0.01
    diag = np.linalg.norm(X.max(axis=1) - X.min(axis=1))
    tol = a.tol * diag
    flags = int(fem.ElementElasticityComputationFlags.Potential) | int(fem.ElementElasticityComputationFlags.Gradient) | int(fem.ElementElasticityComputationFlags.Hessian)
    flags_e = int(fem.ElementElasticityComputationFlags.Potential)

    def potential(y, xhat, with_derivatives):
        U, gU, HU = fem.hyper_elastic_potential(
            E, n, eg, wg, GNeg, mug, lamg, y,
            energy=fem.HyperElasticEnergy.StableNeoHookean,
            flags=flags if with_derivatives else flags_e,
            spd_correction=fem.HyperElasticSpdCorrection.Absolute,
            element=element, order=1, dims=3)
        d = y - xhat
        val = 0.5 / dt**2 * np.dot(d, M * d) + U - np.dot(fext, y)
        if not with_derivatives:
            return val, None, None
        grad = M * d / dt**2 + gU - fext
        H = HU + sp.diags(M / dt**2)
        return val, grad, H

    times, iters = [], []
    for s in range(a.steps):
        t0 = time.perf_counter()
        xn = x.copy()
        xhat = x + dt * v
        y = xhat.copy()
        y[fixed] = xn[fixed]
        k = 0
        for k in range(1, 101):
            f, grad, H = potential(y, xhat, True)
            Hff = H[free][:, free].tocsc()
            dx = np.zeros_like(y)
            dx[free] = spl.spsolve(Hff, -grad[free])
            slope = np.dot(grad, dx)
            alpha = 1.0
            upd = np.abs(dx).max()
            while True:
                yt = y + alpha * dx
                ft, _, _ = potential(yt, xhat, False)
                if ft <= f + 1e-4 * alpha * slope or alpha * upd <= tol or alpha < 1e-8:
                    break
                alpha *= 0.5
            y = yt
            if alpha * upd <= tol:
                break
        v = (y - xn) / dt
        x = y
        times.append(time.perf_counter() - t0)
        iters.append(k)
    tip = x[2::3][X[0, :] > 1 - 1e-9].mean()
    rest = sorted(times[1:]) if len(times) > 1 else times
    print(json.dumps({
        "code": "pbatoolkit",
        "elements": int(E.shape[1]),
        "steps": a.steps,
        "per_step_s": rest[len(rest) // 2],
        "newton_iterations": iters,
        "tip_z": float(tip),
    }))


if __name__ == "__main__":
    main()
