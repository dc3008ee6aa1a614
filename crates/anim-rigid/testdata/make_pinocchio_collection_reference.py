#!/usr/bin/env python3
"""Writes the Pinocchio reference for the example-robot-data collection conformance case.

    pip install pin==4.1.0 example-robot-data==6.0.0
    python3 crates/anim-rigid/testdata/make_pinocchio_collection_reference.py

For every URDF of the collection (by default the gzip'd copies under `robots/`, made by
`make_robot_collection.py`; `--robots DIR` reads `*.urdf` and `*.urdf.gz` under another copy, such
as the installed `example-robot-data/robots`) and for both bases (fixed: the root link welded to
the world; floating: the root link carried by `JointModelFreeFlyer`, named `root_joint`), the
model is built with `pin.buildModelFromXML` (mimic joints left independent, Pinocchio's default)
and 20 samples are drawn from a generator seeded by the CRC-32 of `<path>:<base>`, so that each
robot's samples do not depend on which other robots are present:

- q within the position limits; a limit of magnitude >= 1e10 (e.g. the iris rotors' +-1e16) counts
  as none, and a joint without limits (`continuous`, stored as (cos, sin)) turns in [-pi, pi];
  free flyer: translation in [-1, 1]^3 and a uniformly random unit quaternion (x, y, z, w);
- v in [-2, 2], a in [-3, 3], tau in [-10, 10] (every robot, no scaling by size).

Fixed base, per sample, in this order, little-endian float64 (Pinocchio's layout and conventions):

    q (nq), v (nv), a (nv), tau (nv),
    oMi:  for joints 1..njoints-1, the rotation row by row (9) then the translation (3), after
          `pin.computeJointJacobians` (which runs forward kinematics),
    rnea: `pin.rnea(q, v, a)`, gravity (0, 0, -9.81) included (nv),
    crba: the upper triangle of `pin.crba(q)`, row by row (nv (nv + 1) / 2),
    aba:  `pin.aba(q, v, tau)` (nv).

`data.J` after `computeJointJacobians` (the world Jacobian, 6 x nv) is not stored: its columns
are `Ad(oMi) S` of the stored `oMi` and of each joint's motion subspace `S` (in the header), and
the script checks that this reproduces `data.J` to 1e-13 before writing.

Floating base: sample k has the joint configuration of fixed-base sample k on a random base
placement, so its `oMi` are the root placement times the fixed-base `oMi` and the joint block of
`H` is the fixed-base `H` (both checked to 1e-13). Per sample it stores what those do not give:

    q (nq), v (nv), a (nv), tau (nv), oMi of root_joint (12), rnea (nv),
    the first 6 rows of the upper triangle of `pin.crba(q)` (row r from column r on), aba (nv).

Output (`--out DIR`, default `pinocchio_collection/` beside this script): `index.json`, one line
per robot and base with the model header (per joint: name, Pinocchio joint type, parent, idx_q,
idx_v, width in q and in v, motion subspace `S` column by column; nq, nv, njoints, seed) and the
data file's name, or one line per URDF Pinocchio refuses, with its message; and `<path without .urdf>.<base>.f64.gz` per loaded model (gzip level 9, no file name, time stamp
0). Running the script twice gives identical bytes. `--only PREFIX` keeps the paths starting with
PREFIX (e.g. `--only alex_description` for the models whose licence keeps them out of the
repository: `--robots <site-packages>/cmeel.prefix/share/example-robot-data/robots --only
alex_description --out DIR`, then set `ANIM_ROBOT_COLLECTION` to that robots directory and
`ANIM_ROBOT_COLLECTION_REFERENCE` to DIR for `cargo test -p anim-rigid --features cases --test
pinocchio_collection`).
"""

import argparse
import gzip
import json
import math
import os
import sys
import zlib

import numpy as np
import pinocchio as pin

HERE = os.path.dirname(os.path.abspath(__file__))
SAMPLES = 20
UNBOUNDED = 1e10


def urdfs(root, only):
    out = []
    for d, _, files in os.walk(root):
        for f in files:
            if f.endswith(".urdf") or f.endswith(".urdf.gz"):
                full = os.path.join(d, f)
                rel = os.path.relpath(full, root).replace(os.sep, "/")
                rel = rel[:-3] if rel.endswith(".gz") else rel
                if rel.startswith(only):
                    out.append((rel, full))
    return sorted(out)


def read(path):
    if path.endswith(".gz"):
        with gzip.open(path, "rb") as f:
            return f.read().decode("utf-8")
    with open(path, encoding="utf-8") as f:
        return f.read()


def random_q(model, rng):
    q = np.zeros(model.nq)
    for j in range(1, model.njoints):
        jm = model.joints[j]
        iq, kind = jm.idx_q, jm.shortname()
        if kind == "JointModelFreeFlyer":
            q[iq : iq + 3] = rng.uniform(-1.0, 1.0, 3)
            quat = rng.normal(size=4)
            q[iq + 3 : iq + 7] = quat / np.linalg.norm(quat)
        elif kind.startswith("JointModelRUB"):
            t = rng.uniform(-math.pi, math.pi)
            q[iq : iq + 2] = (math.cos(t), math.sin(t))
        elif jm.nq == 1:
            lo, hi = model.lowerPositionLimit[iq], model.upperPositionLimit[iq]
            if not (abs(lo) < UNBOUNDED and abs(hi) < UNBOUNDED):
                lo, hi = -math.pi, math.pi
            q[iq] = lo + (hi - lo) * rng.random()
        else:
            sys.exit(f"{model.name}: joint {model.names[j]} of type {kind} has no sampling rule")
    return q


def le(x):
    return np.ascontiguousarray(np.asarray(x, dtype="<f8").reshape(-1)).tobytes()


def motion_subspace(model, j):
    """The columns of joint j's motion subspace S in its own frame (linear then angular)."""
    jm = model.joints[j]
    jd = jm.createData()
    jm.calc(jd, pin.neutral(model))
    return np.asarray(jd.S).reshape(6, jm.nv).T


def placement(m):
    return np.concatenate([m.rotation.reshape(-1), m.translation])


def check_jacobian(model, data, subspaces):
    """data.J is Ad(oMi) S, column by column (what the Rust side rebuilds it from)."""
    worst = 0.0
    for j in range(1, model.njoints):
        m = data.oMi[j]
        for k, s in enumerate(subspaces[j - 1]):
            col = m.act(pin.Motion(s)).vector
            worst = max(worst, np.abs(col - data.J[:, model.idx_vs[j] + k]).max())
    if worst > 1e-13 * max(1.0, np.abs(data.J).max(initial=0.0)):
        sys.exit(f"{model.name}: data.J differs from Ad(oMi) S by {worst:e}")


def draw(model, rng):
    q = random_q(model, rng)
    v = rng.uniform(-2.0, 2.0, model.nv)
    a = rng.uniform(-3.0, 3.0, model.nv)
    tau = rng.uniform(-10.0, 10.0, model.nv)
    return q, v, a, tau


def fixed_samples(model, seed):
    """The fixed-base samples (bytes) and their joint configurations."""
    data = model.createData()
    rng = np.random.default_rng(seed)
    subspaces = [motion_subspace(model, j) for j in range(1, model.njoints)]
    iu = np.triu_indices(model.nv)
    chunks = []
    for _ in range(SAMPLES):
        q, v, a, tau = draw(model, rng)
        pin.computeJointJacobians(model, data, q)
        check_jacobian(model, data, subspaces)
        omi = [placement(data.oMi[j]) for j in range(1, model.njoints)]
        rnea = pin.rnea(model, data, q, v, a).copy()
        m = pin.crba(model, data, q).copy()
        ddq = pin.aba(model, data, q, v, tau).copy()
        chunks += [le(x) for x in (q, v, a, tau, *omi, rnea, m[iu], ddq)]
    return b"".join(chunks)


def floating_samples(model, fixed, seed):
    """The floating-base samples (bytes): the joint configurations of the fixed-base samples on a
    random base placement, with what the fixed-base samples do not determine."""
    data = model.createData()
    fdata = fixed.createData()
    rng = np.random.default_rng(seed)
    frng = np.random.default_rng(zlib.crc32(f"{model.name}:fixed".encode()))
    subspaces = [motion_subspace(model, j) for j in range(1, model.njoints)]
    chunks = []
    for _ in range(SAMPLES):
        qj = draw(fixed, frng)[0]
        q, v, a, tau = draw(model, rng)
        q[7:] = qj
        pin.computeJointJacobians(model, data, q)
        check_jacobian(model, data, subspaces)
        m = pin.crba(model, data, q).copy()
        pin.computeJointJacobians(fixed, fdata, qj)
        mf = pin.crba(fixed, fdata, qj)
        root = data.oMi[1]
        worst = max(
            [np.abs(m[6:, 6:] - mf)[np.triu_indices(fixed.nv)].max(initial=0.0) / max(1.0, np.abs(mf).max(initial=0.0))]
            + [np.abs(placement(root * fdata.oMi[j]) - placement(data.oMi[j + 1])).max() for j in range(1, fixed.njoints)]
        )
        if worst > 1e-13:
            sys.exit(f"{model.name}: the floating base is not the fixed base moved ({worst:e})")
        rnea = pin.rnea(model, data, q, v, a).copy()
        ddq = pin.aba(model, data, q, v, tau).copy()
        base_rows = np.concatenate([m[r, r:] for r in range(6)])
        chunks += [le(x) for x in (q, v, a, tau, placement(root), rnea, base_rows, ddq)]
    return b"".join(chunks)


def header(model):
    return [
        [model.names[j], model.joints[j].shortname(), int(model.parents[j]), int(model.idx_qs[j]),
         int(model.idx_vs[j]), int(model.nqs[j]), int(model.nvs[j]),
         [[float(x) for x in s] for s in motion_subspace(model, j)]]
        for j in range(1, model.njoints)
    ]


def write(out, name, payload):
    target = os.path.join(out, name)
    os.makedirs(os.path.dirname(target), exist_ok=True)
    with open(target, "wb") as raw:
        with gzip.GzipFile(filename="", mode="wb", compresslevel=9, fileobj=raw, mtime=0) as gz:
            gz.write(payload)
    return os.path.getsize(target)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--robots", default=os.path.join(HERE, "robots"))
    parser.add_argument("--out", default=os.path.join(HERE, "pinocchio_collection"))
    parser.add_argument("--only", default="")
    args = parser.parse_args()
    entries, total = [], 0
    for rel, path in urdfs(args.robots, args.only):
        xml = read(path)
        try:
            fixed = pin.buildModelFromXML(xml)
            floating = pin.buildModelFromXML(xml, pin.JointModelFreeFlyer())
        except (RuntimeError, ValueError) as e:
            entries.append({"urdf": rel, "refused": str(e).strip()})
            print(f"{rel}: Pinocchio refuses it: {entries[-1]['refused']}")
            continue
        for base, model in (("fixed", fixed), ("floating", floating)):
            seed = zlib.crc32(f"{rel}:{base}".encode())
            fixed.name = floating.name = rel
            payload = fixed_samples(model, seed) if base == "fixed" else floating_samples(model, fixed, seed)
            name = f"{rel[: -len('.urdf')]}.{base}.f64.gz"
            total += write(args.out, name, payload)
            entries.append(
                {"urdf": rel, "base": base, "data": name, "seed": seed, "samples": SAMPLES, "nq": model.nq,
                 "nv": model.nv, "njoints": model.njoints, "joints": header(model)}
            )
    os.makedirs(args.out, exist_ok=True)
    index = os.path.join(args.out, "index.json")
    with open(index, "w", encoding="utf-8") as f:
        f.write('{"generator": "crates/anim-rigid/testdata/make_pinocchio_collection_reference.py",\n')
        f.write(f' "pinocchio_version": "{pin.__version__}", "samples": {SAMPLES},\n "models": [\n')
        f.write(",\n".join(json.dumps(e, separators=(",", ":")) for e in entries))
        f.write("\n]}\n")
    total += os.path.getsize(index)
    print(f"wrote {index} and {sum('data' in e for e in entries)} data files, {total} bytes in all")


if __name__ == "__main__":
    main()
