"""Peer benchmark: Jan Bender's PositionBasedDynamics (pyPBD wheel) on the benchmark cloth.

The same cloth as anim_pbd::scenes::benchmark_cloth: n x n particles of 1 kg on a 1 m square,
horizontal (pyPBD is y-up, so the grid is rotated into the x-z plane), pinned at the two
corners of one edge, XPBD distance constraints on every triangle edge (stiffness 1e5, i.e.
compliance 1e-5) and XPBD isometric bending on every interior edge (stiffness 50), dt = 1/60,
one substep, `--iterations` solver iterations. Prints one JSON line per run:
{"code": "pypbd", "version": ..., "n": ..., "iterations": ..., "constraints": ...,
 "per_step_s": ..., "min_height": ..., "threads": ...}
Threads: pyPBD parallelises some loops with OpenMP; OMP_NUM_THREADS is set by the caller.
"""

import argparse
import json
import math
import time

import numpy as np
import pypbd as pbd


def rotation_x(angle):
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def build(n, iterations):
    sim = pbd.Simulation.getCurrent()
    sim.initDefault()
    model = sim.getModel()
    tri = model.addRegularTriangleModel(n, n, [0.0, 0.0, 0.0], rotation_x(math.pi / 2), [1.0, 1.0], testMesh=False)
    pd = model.getParticles()
    pd.setMass(0, 0.0)
    pd.setMass(n - 1, 0.0)
    # simModel 4: XPBD distance constraints; bendingModel 3: XPBD isometric bending.
    model.addClothConstraints(tri, 4, 1e5, 1e5, 1e5, 1e5, 0.3, 0.3, False, False)
    model.addBendingConstraints(tri, 3, 50.0)
    ts = sim.getTimeStep()
    ts.setValueUInt(pbd.TimeStepController.NUM_SUB_STEPS, 1)
    ts.setValueUInt(pbd.TimeStepController.MAX_ITERATIONS, iterations)
    pbd.TimeManager.getCurrent().setTimeStepSize(1.0 / 60.0)
    return sim, model, ts


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--n", type=int, default=50)
    ap.add_argument("--iterations", type=int, default=5)
    ap.add_argument("--steps", type=int, default=20)
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--threads", type=int, default=1)
    a = ap.parse_args()
    times = []
    min_h = float("nan")
    constraints = 0
    for rep in range(a.repeats + 1):
        sim, model, ts = build(a.n, a.iterations)
        constraints = len(model.getConstraints())
        ts.step(model)  # warm up
        t = time.perf_counter()
        for _ in range(a.steps):
            ts.step(model)
        if rep > 0:
            times.append((time.perf_counter() - t) / a.steps)
        pd = model.getParticles()
        min_h = min(float(pd.getPosition(i)[1]) for i in range(pd.size()))
        sim.reset()
        model.cleanup()
    times.sort()
    print(json.dumps({
        "code": "pypbd",
        "version": "2.2.2",
        "n": a.n,
        "iterations": a.iterations,
        "constraints": constraints,
        "per_step_s": times[len(times) // 2],
        "min_height": min_h,
        "threads": a.threads,
    }))


if __name__ == "__main__":
    main()
