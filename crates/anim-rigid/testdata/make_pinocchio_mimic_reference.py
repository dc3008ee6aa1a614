#!/usr/bin/env python3
"""Writes the Pinocchio reference for coupled (mimic) joints used by anim-rigid's tests and
`cargo xtask conformance`.

    pip install pin==4.1.0 example-robot-data==6.0.0
    python3 crates/anim-rigid/testdata/make_pinocchio_mimic_reference.py

For every URDF of the committed example-robot-data collection (`robots/`, gzip'd) that has a
`<mimic>` element, it builds `pin.buildModelFromXML(xml, mimic=True)`. Robots Pinocchio refuses
(a mimic joint whose master comes later in the depth-first order: romeo, talos_full_v2) are
listed with Pinocchio's message, so the Rust side checks it refuses them too; those whose
`<mimic>` elements are all on fixed joints (talos) only with their sizes. For the others it
draws 20 seeded samples — q from `pin.randomConfiguration` (limits of unbounded entries set to
[-3, 3] first; Pinocchio's layout, continuous joints as (cos, sin)), v in [-2, 2], a in [-3, 3],
tau in [-10, 10] — and writes `pinocchio_mimic.json.gz` with, per sample:

- `placements`: `data.oMi` of every joint after `pin.forwardKinematics` (rotation row-major,
  then translation: 12 numbers per joint);
- `jacobian`: `pin.computeJointJacobians` (`data.J`, 6 x nvExtended, column-major), whose
  columns are the world motion of every joint taken independently (`idx_vExtended`);
- `joint_jacobians`: `pin.getJointJacobian(..., WORLD)` (6 x nv, column-major) of every mimic
  joint, where each mimic column is added, times its multiplier, to its master's;
- `rnea`: `pin.rnea(model, data, q, v, a)`;
- `crba`: `pin.crba(model, data, q)`, upper triangle mirrored, nv x nv row-major;
- `nle`: `pin.nonLinearEffects(model, data, q, v)`;
- `fd`: `numpy.linalg.solve(crba, tau - nle)` (Pinocchio's `aba` refuses mimic joints);
- `kinetic_energy`: `v·Mv / 2` with that `crba` (`pin.computeKineticEnergy` refuses mimic joints);
- `potential_energy`: `-Σ m_i g·c_i` over the moving bodies (joint 1 on, as Pinocchio), centres of mass `c_i` placed by
  `data.oMi` (`pin.computePotentialEnergy` refuses mimic joints too).

The model section lists every joint (name, parent, idx_q, idx_v, idx_vExtended, and for mimic
joints the master, multiplier and offset).
"""

import glob
import gzip
import json
import os

import numpy as np
import pinocchio as pin

HERE = os.path.dirname(os.path.abspath(__file__))
SAMPLES = 20
SEED = 20261127


def flat(m):
    return [float(x) for x in np.asarray(m).flatten(order="F")]


def placement(p):
    return [float(x) for x in p.rotation.flatten(order="C")] + [float(x) for x in p.translation]


def robot(rel, xml, rng):
    model = pin.buildModelFromXML(xml, mimic=True)
    data = model.createData()
    joints = []
    for i in range(model.njoints):
        j = model.joints[i]
        entry = {
            "name": model.names[i],
            "parent": int(model.parents[i]),
            "idx_q": int(j.idx_q),
            "idx_v": int(j.idx_v),
            "idx_v_extended": int(j.idx_vExtended),
            "nv_extended": int(j.nvExtended),
        }
        if j.shortname() == "JointModelMimic":
            k = list(model.mimicking_joints).index(i)
            entry["master"] = model.names[model.mimicked_joints[k]]
            entry["multiplier"] = float(j.extract().scaling)
            entry["offset"] = float(j.extract().offset)
        joints.append(entry)
    lower = np.where(np.isfinite(model.lowerPositionLimit), model.lowerPositionLimit, -3.0)
    upper = np.where(np.isfinite(model.upperPositionLimit), model.upperPositionLimit, 3.0)
    model.lowerPositionLimit = lower
    model.upperPositionLimit = upper
    mimics = [i for i in range(model.njoints) if model.joints[i].shortname() == "JointModelMimic"]
    samples = []
    for _ in range(SAMPLES):
        q = pin.randomConfiguration(model)
        v = rng.uniform(-2, 2, model.nv)
        a = rng.uniform(-3, 3, model.nv)
        tau = rng.uniform(-10, 10, model.nv)
        pin.forwardKinematics(model, data, q)
        placements = [placement(data.oMi[i]) for i in range(model.njoints)]
        J = pin.computeJointJacobians(model, data, q).copy()
        joint_jacobians = {model.names[i]: flat(pin.getJointJacobian(model, data, i, pin.WORLD)) for i in mimics}
        tau_rnea = pin.rnea(model, data, q, v, a).copy()
        M = pin.crba(model, data, q).copy()
        M = np.triu(M) + np.triu(M, 1).T
        nle = pin.nonLinearEffects(model, data, q, v).copy()
        fd = np.linalg.solve(M, tau - nle)
        samples.append({
            "q": [float(x) for x in q],
            "v": [float(x) for x in v],
            "a": [float(x) for x in a],
            "tau": [float(x) for x in tau],
            "placements": placements,
            "jacobian": flat(J),
            "joint_jacobians": joint_jacobians,
            "rnea": [float(x) for x in tau_rnea],
            "crba": [float(x) for x in M.flatten()],
            "nle": [float(x) for x in nle],
            "fd": [float(x) for x in fd],
            "kinetic_energy": float(0.5 * v @ M @ v),
            "potential_energy": float(sum(
                -model.inertias[i].mass * model.gravity.linear @ data.oMi[i].act(model.inertias[i].lever)
                for i in range(1, model.njoints)
            )),
        })
    return {
        "urdf": rel,
        "nq": model.nq,
        "nv": model.nv,
        "nv_extended": int(model.nvExtended),
        "joints": joints,
        "samples": samples,
    }


def main():
    rng = np.random.default_rng(SEED)
    pin.seed(SEED)
    robots, refused, uncoupled = [], [], []
    for path in sorted(glob.glob(os.path.join(HERE, "robots", "*", "*", "*.urdf.gz"))):
        rel = os.path.relpath(path, HERE)
        xml = gzip.open(path).read().decode()
        if "<mimic" not in xml:
            continue
        try:
            pin.buildModelFromXML(xml, mimic=True)
        except ValueError as e:
            refused.append({"urdf": rel, "pinocchio": str(e).strip().splitlines()[-1]})
            continue
        model = pin.buildModelFromXML(xml, mimic=True)
        if len(model.mimicking_joints) == 0:
            # Every <mimic> is on a fixed joint: nothing is coupled, only the sizes are checked.
            uncoupled.append({"urdf": rel, "nq": model.nq, "nv": model.nv})
            continue
        robots.append(robot(rel, xml, rng))
    out = {
        "pinocchio": pin.__version__,
        "samples": SAMPLES,
        "seed": SEED,
        "robots": robots,
        "refused": refused,
        "uncoupled": uncoupled,
    }
    text = json.dumps(out, separators=(",", ":"))
    target = os.path.join(HERE, "pinocchio_mimic.json.gz")
    with gzip.GzipFile(target, "wb", mtime=0) as f:
        f.write(text.encode())
    print(f"wrote {target}: {len(robots)} robots, {len(refused)} refused, {os.path.getsize(target)} bytes")


if __name__ == "__main__":
    main()
