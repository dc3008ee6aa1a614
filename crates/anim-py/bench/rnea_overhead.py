"""Per-call time of RNEA on the Franka Panda called from a Python loop: anim.rigid.rnea against
pinocchio.rnea (when the `pin` package is installed).

    python crates/anim-py/bench/rnea_overhead.py [--calls 20000] [--repeats 7]

Both load crates/anim-rigid/testdata/panda.urdf with the fingers locked at 0 (7 degrees of
freedom) and evaluate the same random (q, v, a) each call, passed as float64 numpy arrays. Each
repeat times `calls` calls with time.perf_counter; the script prints the median and the range
(min to max) of the per-call time over the repeats, and checks that both give the same torques.
"""

import argparse
import os
import statistics
import time

import numpy as np

import anim

HERE = os.path.dirname(os.path.abspath(__file__))
URDF = os.path.join(HERE, "..", "..", "anim-rigid", "testdata", "panda.urdf")
FINGERS = ["panda_finger_joint1", "panda_finger_joint2"]


def per_call(fn, calls, repeats):
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        for _ in range(calls):
            fn()
        times.append((time.perf_counter() - start) / calls)
    return times


def report(name, times):
    us = [t * 1e6 for t in times]
    print(f"{name:<24} median {statistics.median(us):7.3f} us   range {min(us):7.3f} .. {max(us):7.3f} us")
    return statistics.median(us)


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--calls", type=int, default=20000)
    parser.add_argument("--repeats", type=int, default=7)
    args = parser.parse_args()

    model = anim.rigid.build_model_from_urdf(URDF, locked_joints=FINGERS)
    data = model.create_data()
    rng = np.random.default_rng(0)
    q = rng.uniform(model.lower_position_limit, model.upper_position_limit)
    v = rng.uniform(-2, 2, model.nv)
    a = rng.uniform(-3, 3, model.nv)
    tau = anim.rigid.rnea(model, data, q, v, a)
    rnea = anim.rigid.rnea
    ours = report("anim.rigid.rnea", per_call(lambda: rnea(model, data, q, v, a), args.calls, args.repeats))

    try:
        import pinocchio as pin
    except ImportError:
        print("pinocchio is not installed (pip install pin): no comparison")
        return
    full = pin.buildModelFromUrdf(URDF)
    locked = [full.getJointId(n) for n in FINGERS]
    pmodel = pin.buildReducedModel(full, locked, pin.neutral(full))
    pdata = pmodel.createData()
    np.testing.assert_allclose(pin.rnea(pmodel, pdata, q, v, a), tau, atol=1e-9)
    prnea = pin.rnea
    theirs = report(f"pinocchio.rnea ({pin.__version__})", per_call(lambda: prnea(pmodel, pdata, q, v, a), args.calls, args.repeats))
    print(f"ratio anim / pinocchio (medians): {ours / theirs:.2f}")


if __name__ == "__main__":
    main()
