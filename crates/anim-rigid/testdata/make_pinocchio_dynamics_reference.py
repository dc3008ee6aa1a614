#!/usr/bin/env python3
"""Writes the Pinocchio dynamics reference used by anim-rigid's tests and `cargo xtask conformance`.

    pip install pin==4.1.0 example-robot-data==6.0.0
    python3 crates/anim-rigid/testdata/make_pinocchio_dynamics_reference.py

It first writes `chain32.urdf`, a 32-joint serial chain (revolute joints about x, y, z and an
unaligned axis, four prismatic joints, rotated joint origins, links with off-diagonal inertias and
offset centres of mass, and a fixed tool link merged into the last body), from closed-form
expressions (no random numbers), so that both libraries load the same model from the same file.

Then, for the Franka Panda (fingers locked at 0, 7 DoF), the UR5, the chain and the Panda on a
free-flyer base (`JointModelFreeFlyer`, nq = 14, nv = 13), it draws 50 seeded samples of
(q, v, a, tau) — q uniform within the joint limits (free-flyer: translation in [-1, 1]^3 and a
uniformly random unit quaternion), v in [-2, 2], a in [-3, 3], tau in [-10, 10] — and writes
`pinocchio_dynamics_<model>.json` with, per sample:

- `rnea`: `pin.rnea(model, data, q, v, a)`, gravity (0, 0, -9.81) included;
- `crba`: `pin.crba(model, data, q)` with its upper triangle mirrored, n x n row-major;
- `nle`: `pin.nonLinearEffects(model, data, q, v)` (the bias term C(q, v));
- `gravity`: `pin.computeGeneralizedGravity(model, data, q)`;
- `aba`: `pin.aba(model, data, q, v, tau)`;
- `kinetic_energy`, `potential_energy`: `pin.computeKineticEnergy`, `pin.computePotentialEnergy`.

The model section lists the joints (name, type, parent, index in q and v, inertia) so the Rust
side checks it built the same model before comparing numbers.
"""

import filecmp
import json
import math
import os
import site
import sys

import numpy as np
import pinocchio as pin

HERE = os.path.dirname(os.path.abspath(__file__))
SAMPLES = 50
SEED = 20240611
CHAIN_JOINTS = 32


def fmt(x):
    return f"{x:.6f}".rstrip("0").rstrip(".") if x != 0 else "0"


def chain_urdf():
    """The 32-joint chain, from closed-form expressions of the joint index."""
    axes = ["1 0 0", "0 1 0", "0 0 1", "0.48 0.6 0.64"]
    lines = ['<?xml version="1.0"?>', '<!-- Written by make_pinocchio_dynamics_reference.py: a 32-joint serial chain for the dynamics conformance. -->', '<robot name="chain32">', '  <link name="base"/>']
    parent = "base"
    for k in range(CHAIN_JOINTS):
        link = f"link{k + 1}"
        mass = 0.4 + 0.3 * math.sin(0.7 * k) ** 2
        com = (0.05 + 0.02 * math.cos(k), 0.01 * math.sin(1.3 * k), 0.03 * math.cos(0.4 * k))
        ixx = 0.004 + 0.002 * math.sin(k) ** 2
        iyy = 0.005 + 0.002 * math.cos(1.7 * k) ** 2
        izz = 0.003 + 0.001 * math.sin(0.3 * k) ** 2
        ixy = 0.0004 * math.sin(2.1 * k)
        ixz = -0.0003 * math.cos(0.9 * k)
        iyz = 0.0002 * math.sin(1.1 * k)
        lines += [
            f'  <link name="{link}">',
            "    <inertial>",
            f'      <origin xyz="{fmt(com[0])} {fmt(com[1])} {fmt(com[2])}" rpy="{fmt(0.1 * math.sin(k))} 0 {fmt(0.2 * math.cos(k))}"/>',
            f'      <mass value="{fmt(mass)}"/>',
            f'      <inertia ixx="{fmt(ixx)}" ixy="{fmt(ixy)}" ixz="{fmt(ixz)}" iyy="{fmt(iyy)}" iyz="{fmt(iyz)}" izz="{fmt(izz)}"/>',
            "    </inertial>",
            "  </link>",
        ]
        prismatic = k % 8 == 5
        kind = "prismatic" if prismatic else "revolute"
        lower, upper = (-0.2, 0.2) if prismatic else (-2.6, 2.6)
        xyz = (0.0 if k == 0 else 0.12 + 0.01 * (k % 3), 0.01 * math.sin(k), 0.02 * math.cos(0.5 * k))
        rpy = (0.3 * math.sin(1.1 * k), 0.25 * math.cos(0.7 * k), 0.2 * math.sin(0.3 * k + 1.0))
        lines += [
            f'  <joint name="joint{k + 1}" type="{kind}">',
            f'    <parent link="{parent}"/>',
            f'    <child link="{link}"/>',
            f'    <origin xyz="{fmt(xyz[0])} {fmt(xyz[1])} {fmt(xyz[2])}" rpy="{fmt(rpy[0])} {fmt(rpy[1])} {fmt(rpy[2])}"/>',
            f'    <axis xyz="{axes[k % 4]}"/>',
            f'    <limit lower="{fmt(lower)}" upper="{fmt(upper)}" effort="50" velocity="3"/>',
            "  </joint>",
        ]
        parent = link
    lines += [
        '  <link name="tool">',
        "    <inertial>",
        '      <origin xyz="0.02 0 0.01"/>',
        '      <mass value="0.3"/>',
        '      <inertia ixx="0.0005" ixy="0" ixz="0" iyy="0.0006" iyz="0" izz="0.0004"/>',
        "    </inertial>",
        "  </link>",
        '  <joint name="tool_joint" type="fixed">',
        f'    <parent link="{parent}"/>',
        '    <child link="tool"/>',
        '    <origin xyz="0.1 0 0" rpy="0 1.5707963267948966 0"/>',
        "  </joint>",
        "</robot>",
    ]
    return "\n".join(lines) + "\n"


def robots_dir():
    for base in site.getsitepackages() + [site.getusersitepackages()]:
        d = os.path.join(base, "cmeel.prefix", "share", "example-robot-data", "robots")
        if os.path.isdir(d):
            return d
    sys.exit("example-robot-data is not installed (pip install example-robot-data==6.0.0)")


MODELS = [
    {"name": "panda", "urdf": "panda.urdf", "installed": "panda_description/urdf/panda.urdf",
     "locked_joints": ["panda_finger_joint1", "panda_finger_joint2"], "floating": False},
    {"name": "ur5", "urdf": "ur5_robot.urdf", "installed": "ur_description/urdf/ur5_robot.urdf",
     "locked_joints": [], "floating": False},
    {"name": "chain32", "urdf": "chain32.urdf", "installed": None, "locked_joints": [], "floating": False},
    {"name": "panda_floating", "urdf": "panda.urdf", "installed": "panda_description/urdf/panda.urdf",
     "locked_joints": ["panda_finger_joint1", "panda_finger_joint2"], "floating": True},
]


def build(spec):
    path = os.path.join(HERE, spec["urdf"])
    if spec["installed"]:
        installed = os.path.join(robots_dir(), spec["installed"])
        if not filecmp.cmp(path, installed, shallow=False):
            sys.exit(f"{path} differs from the installed {installed}")
    if spec["floating"]:
        full = pin.buildModelFromUrdf(path, pin.JointModelFreeFlyer())
    else:
        full = pin.buildModelFromUrdf(path)
    if spec["locked_joints"]:
        ids = [full.getJointId(n) for n in spec["locked_joints"]]
        return pin.buildReducedModel(full, ids, pin.neutral(full))
    return full


def floats(x):
    return [float(v) for v in np.asarray(x).reshape(-1)]


def random_q(model, rng):
    q = np.zeros(model.nq)
    for j in range(1, model.njoints):
        jm = model.joints[j]
        iq, nq = jm.idx_q, jm.nq
        if jm.shortname() == "JointModelFreeFlyer":
            q[iq : iq + 3] = rng.uniform(-1.0, 1.0, 3)
            quat = rng.normal(size=4)
            q[iq + 3 : iq + 7] = quat / np.linalg.norm(quat)
        else:
            lo = model.lowerPositionLimit[iq : iq + nq]
            hi = model.upperPositionLimit[iq : iq + nq]
            q[iq : iq + nq] = lo + (hi - lo) * rng.random(nq)
    return q


def main():
    with open(os.path.join(HERE, "chain32.urdf"), "w") as f:
        f.write(chain_urdf())
    rng = np.random.default_rng(SEED)
    for spec in MODELS:
        model = build(spec)
        data = model.createData()
        out = {
            "generator": "crates/anim-rigid/testdata/make_pinocchio_dynamics_reference.py",
            "pinocchio_version": pin.__version__,
            "model": spec["name"],
            "urdf": spec["urdf"],
            "locked_joints": spec["locked_joints"],
            "floating_base": spec["floating"],
            "gravity": floats(model.gravity.linear),
            "nq": model.nq,
            "nv": model.nv,
            "joints": [
                {
                    "name": model.names[j],
                    "type": model.joints[j].shortname(),
                    "parent": int(model.parents[j]),
                    "idx_q": int(model.idx_qs[j]),
                    "idx_v": int(model.idx_vs[j]),
                    "mass": float(model.inertias[j].mass),
                    "com": floats(model.inertias[j].lever),
                    "inertia": floats(model.inertias[j].inertia),
                }
                for j in range(model.njoints)
            ],
            "samples": [],
        }
        for _ in range(SAMPLES):
            q = random_q(model, rng)
            v = rng.uniform(-2.0, 2.0, model.nv)
            a = rng.uniform(-3.0, 3.0, model.nv)
            tau = rng.uniform(-10.0, 10.0, model.nv)
            rnea = pin.rnea(model, data, q, v, a).copy()
            m = pin.crba(model, data, q).copy()
            m = np.triu(m) + np.triu(m, 1).T
            nle = pin.nonLinearEffects(model, data, q, v).copy()
            grav = pin.computeGeneralizedGravity(model, data, q).copy()
            ddq = pin.aba(model, data, q, v, tau).copy()
            ke = pin.computeKineticEnergy(model, data, q, v)
            pe = pin.computePotentialEnergy(model, data, q)
            out["samples"].append(
                {
                    "q": floats(q), "v": floats(v), "a": floats(a), "tau": floats(tau),
                    "rnea": floats(rnea), "crba": floats(m), "nle": floats(nle), "gravity": floats(grav),
                    "aba": floats(ddq), "kinetic_energy": float(ke), "potential_energy": float(pe),
                }
            )
        target = os.path.join(HERE, f"pinocchio_dynamics_{spec['name']}.json")
        with open(target, "w") as f:
            json.dump(out, f, separators=(",", ":"))
            f.write("\n")
        print(f"wrote {target}: nq={model.nq}, nv={model.nv}, {SAMPLES} samples")


if __name__ == "__main__":
    main()
