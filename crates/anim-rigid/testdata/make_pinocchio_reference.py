#!/usr/bin/env python3
"""Writes the Pinocchio kinematics reference used by anim-rigid's tests and `cargo xtask conformance`.

    pip install pin==4.1.0 example-robot-data==6.0.0
    python3 crates/anim-rigid/testdata/make_pinocchio_reference.py

For the Franka Panda (fingers locked at 0 with `buildReducedModel`, a 7-DoF arm) and the UR5, it
loads the URDF committed next to this script (copied from example-robot-data 6.0.0; the script
checks the copy is byte-identical to the installed one), draws 50 configurations uniformly within
the joint limits (seeded) and a velocity per configuration, and writes
`pinocchio_<robot>.json` with, per configuration:

- `joint_placements`: `data.oMi` of every joint (universe included);
- `frame_placements`: `data.oMf` of every frame (after `framesForwardKinematics`);
- `jacobians`: `getFrameJacobian` in WORLD and LOCAL for every JOINT frame and the tool frames,
  and LOCAL_WORLD_ALIGNED for the tool frames (after `computeJointJacobians`);
- `jacobian_dots`: `getFrameJacobianTimeVariation` of the tool frames in the three reference
  frames (after `computeJointJacobiansTimeVariation(q, v)`).

Placements are `[R row-major (9), t (3)]`; Jacobians are 6 x nv row-major, linear rows first.
The model section lists joints (name, type, parent, placement, inertia) and frames (name, type,
parent joint, placement) so that the Rust side can check it built the same model.
"""

import filecmp
import json
import os
import site
import sys

import numpy as np
import pinocchio as pin

HERE = os.path.dirname(os.path.abspath(__file__))
SAMPLES = 50
SEED = 20240607

ROBOTS = [
    {
        "robot": "panda",
        "urdf": "panda.urdf",
        "installed": "panda_description/urdf/panda.urdf",
        "locked_joints": ["panda_finger_joint1", "panda_finger_joint2"],
        "tool_frames": ["panda_hand_tcp", "panda_hand"],
    },
    {
        "robot": "ur5",
        "urdf": "ur5_robot.urdf",
        "installed": "ur_description/urdf/ur5_robot.urdf",
        "locked_joints": [],
        "tool_frames": ["tool0", "ee_link"],
    },
]


def robots_dir():
    for base in site.getsitepackages() + [site.getusersitepackages()]:
        d = os.path.join(base, "cmeel.prefix", "share", "example-robot-data", "robots")
        if os.path.isdir(d):
            return d
    sys.exit("example-robot-data is not installed (pip install example-robot-data==6.0.0)")


def se3(m):
    return [float(x) for x in np.asarray(m.rotation).reshape(-1)] + [float(x) for x in m.translation]


def mat(j):
    return [float(x) for x in np.asarray(j).reshape(-1)]


def frame_type(t):
    return {
        pin.FrameType.JOINT: "JOINT",
        pin.FrameType.FIXED_JOINT: "FIXED_JOINT",
        pin.FrameType.BODY: "BODY",
        pin.FrameType.OP_FRAME: "OP_FRAME",
    }.get(t, str(t))


def build(spec):
    path = os.path.join(HERE, spec["urdf"])
    installed = os.path.join(robots_dir(), spec["installed"])
    if not filecmp.cmp(path, installed, shallow=False):
        sys.exit(f"{path} differs from the installed {installed}")
    full = pin.buildModelFromUrdf(path)
    if spec["locked_joints"]:
        ids = [full.getJointId(n) for n in spec["locked_joints"]]
        model = pin.buildReducedModel(full, ids, pin.neutral(full))
    else:
        model = full
    return path, model


def main():
    rng = np.random.default_rng(SEED)
    for spec in ROBOTS:
        path, model = build(spec)
        data = model.createData()
        joint_frames = [f.name for f in model.frames if f.type == pin.FrameType.JOINT]
        jac_frames = joint_frames + spec["tool_frames"]
        fid = {name: model.getFrameId(name) for name in jac_frames}
        out = {
            "generator": "crates/anim-rigid/testdata/make_pinocchio_reference.py",
            "pinocchio_version": pin.__version__,
            "example_robot_data_version": "6.0.0",
            "robot": spec["robot"],
            "urdf": spec["urdf"],
            "locked_joints": spec["locked_joints"],
            "nq": model.nq,
            "nv": model.nv,
            "joints": [
                {
                    "name": model.names[j],
                    "type": model.joints[j].shortname(),
                    "parent": int(model.parents[j]),
                    "idx_q": int(model.idx_qs[j]),
                    "idx_v": int(model.idx_vs[j]),
                    "placement": se3(model.jointPlacements[j]),
                    "mass": float(model.inertias[j].mass),
                    "com": [float(x) for x in model.inertias[j].lever],
                    "inertia": mat(model.inertias[j].inertia),
                    "lower": [float(x) for x in model.lowerPositionLimit[model.idx_qs[j] : model.idx_qs[j] + model.nqs[j]]],
                    "upper": [float(x) for x in model.upperPositionLimit[model.idx_qs[j] : model.idx_qs[j] + model.nqs[j]]],
                }
                for j in range(model.njoints)
            ],
            "frames": [
                {"name": f.name, "type": frame_type(f.type), "parent_joint": int(f.parentJoint), "placement": se3(f.placement)}
                for f in model.frames
            ],
            "jacobian_frames": jac_frames,
            "tool_frames": spec["tool_frames"],
            "samples": [],
        }
        lo, hi = model.lowerPositionLimit, model.upperPositionLimit
        for _ in range(SAMPLES):
            q = lo + (hi - lo) * rng.random(model.nq)
            v = rng.uniform(-1.0, 1.0, model.nv)
            pin.framesForwardKinematics(model, data, q)
            pin.computeJointJacobians(model, data, q)
            sample = {
                "q": [float(x) for x in q],
                "v": [float(x) for x in v],
                "joint_placements": [se3(m) for m in data.oMi],
                "frame_placements": [se3(m) for m in data.oMf],
                "jacobians": {},
                "jacobian_dots": {},
            }
            for name in jac_frames:
                entry = {
                    "WORLD": mat(pin.getFrameJacobian(model, data, fid[name], pin.ReferenceFrame.WORLD)),
                    "LOCAL": mat(pin.getFrameJacobian(model, data, fid[name], pin.ReferenceFrame.LOCAL)),
                }
                if name in spec["tool_frames"]:
                    entry["LOCAL_WORLD_ALIGNED"] = mat(
                        pin.getFrameJacobian(model, data, fid[name], pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)
                    )
                sample["jacobians"][name] = entry
            pin.computeJointJacobiansTimeVariation(model, data, q, v)
            pin.updateFramePlacements(model, data)
            for name in spec["tool_frames"]:
                sample["jacobian_dots"][name] = {
                    rf: mat(pin.getFrameJacobianTimeVariation(model, data, fid[name], getattr(pin.ReferenceFrame, rf)))
                    for rf in ["WORLD", "LOCAL", "LOCAL_WORLD_ALIGNED"]
                }
            out["samples"].append(sample)
        target = os.path.join(HERE, f"pinocchio_{spec['robot']}.json")
        with open(target, "w") as f:
            json.dump(out, f, separators=(",", ":"))
            f.write("\n")
        print(f"wrote {target}: nq={model.nq}, {model.njoints} joints, {len(model.frames)} frames, {SAMPLES} samples")


if __name__ == "__main__":
    main()
