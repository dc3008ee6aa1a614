"""The Franka Panda's inverse and forward dynamics with anim.rigid, checked against Pinocchio
when the `pin` package is installed.

    python crates/anim-py/examples/robot_dynamics.py

Loads crates/anim-rigid/testdata/panda.urdf (fingers locked: 7 degrees of freedom), draws random
configurations, velocities and accelerations, and prints RNEA torques, the CRBA mass matrix's
diagonal, ABA accelerations, the tool frame's placement and its Jacobian. With Pinocchio it also
prints the largest difference of each quantity between the two libraries.
"""

import os

import numpy as np

import anim
from anim import rigid

HERE = os.path.dirname(os.path.abspath(__file__))
URDF = os.path.join(HERE, "..", "..", "anim-rigid", "testdata", "panda.urdf")
FINGERS = ["panda_finger_joint1", "panda_finger_joint2"]


def main():
    model = rigid.build_model_from_urdf(URDF, locked_joints=FINGERS)
    data = model.create_data()
    print(model)
    tool = model.get_frame_id("panda_hand_tcp")
    rng = np.random.default_rng(7)
    samples = []
    for k in range(5):
        q = rigid.random_configuration(model, seed=k)
        v = rng.uniform(-2, 2, model.nv)
        a = rng.uniform(-3, 3, model.nv)
        tau = rigid.rnea(model, data, q, v, a)
        M = rigid.crba(model, data, q)
        ddq = rigid.aba(model, data, q, v, tau)
        rigid.frames_forward_kinematics(model, data, q)
        oMtool = rigid.frame_placement(model, data, tool)
        J = rigid.compute_frame_jacobian(model, data, q, tool, rigid.LOCAL_WORLD_ALIGNED)
        samples.append((q, v, a, tau, M, ddq, oMtool, J))
        print(f"sample {k}: tau = {np.array2string(tau, precision=3)}")
        print(f"          diag M = {np.array2string(np.diag(M), precision=4)}")
        print(f"          |ddq - a| = {np.abs(ddq - a).max():.2e} (ABA inverts RNEA)")
        print(f"          tool at {np.array2string(oMtool[:3, 3], precision=4)}")

    try:
        import pinocchio as pin
    except ImportError:
        print("pinocchio is not installed (pip install pin): no comparison")
        return
    full = pin.buildModelFromUrdf(URDF)
    pmodel = pin.buildReducedModel(full, [full.getJointId(n) for n in FINGERS], pin.neutral(full))
    pdata = pmodel.createData()
    ptool = pmodel.getFrameId("panda_hand_tcp")
    worst = {"rnea": 0.0, "crba": 0.0, "aba": 0.0, "placement": 0.0, "jacobian": 0.0}
    for q, v, a, tau, M, ddq, oMtool, J in samples:
        worst["rnea"] = max(worst["rnea"], np.abs(pin.rnea(pmodel, pdata, q, v, a) - tau).max())
        Mp = pin.crba(pmodel, pdata, q)
        Mp = np.triu(Mp) + np.triu(Mp, 1).T
        worst["crba"] = max(worst["crba"], np.abs(Mp - M).max())
        worst["aba"] = max(worst["aba"], np.abs(pin.aba(pmodel, pdata, q, v, tau) - ddq).max())
        pin.framesForwardKinematics(pmodel, pdata, q)
        worst["placement"] = max(worst["placement"], np.abs(pdata.oMf[ptool].homogeneous - oMtool).max())
        Jp = pin.computeFrameJacobian(pmodel, pdata, q, ptool, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)
        worst["jacobian"] = max(worst["jacobian"], np.abs(Jp - J).max())
    print(f"Pinocchio {pin.__version__}, largest differences over {len(samples)} samples:")
    for name, value in worst.items():
        print(f"  {name:<10} {value:.1e}")


if __name__ == "__main__":
    main()
