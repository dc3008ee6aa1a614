#!/usr/bin/env python3
"""Writes the forward-dynamics accuracy reference used by anim-rigid's ABA accuracy test and by
`cargo xtask conformance`.

    pip install pin==4.1.0 example-robot-data==6.0.0
    python3 crates/anim-rigid/testdata/make_pinocchio_aba_reference.py

For iCub, TIAGo (no hand) and the human model of example-robot-data (the gzip'd URDFs under
`robots/`), each on a fixed base and on a free-flyer base (`JointModelFreeFlyer`), it draws 20
seeded samples of (q, v, tau) — q uniform within the joint limits (unbounded revolute joints:
an angle in [-pi, pi]; free-flyer: translation in [-1, 1]^3 and a uniformly random unit
quaternion), v in [-2, 2], tau in [-10, 10] — and writes `pinocchio_aba_accuracy.json` with,
per sample:

- `q` in anim-rigid's layout (the angle of an unbounded revolute joint) and `q_pinocchio`
  (its `(cos, sin)`);
- `reference`: the accelerations `H(q)^-1 (tau - C(q, v))`, independent of any articulated-body
  algorithm: a Cholesky solve with Pinocchio's `crba` and `nonLinearEffects` in double
  precision, then eight steps of iterative refinement whose residual `tau - RNEA(q, v, a)` is
  evaluated in 40-digit arithmetic (mpmath) by the recursive Newton-Euler algorithm below, from
  the model's joint placements and inertias; the last correction (stored as
  `reference_last_correction`, relative to the largest entry) must be below 1e-18, so the
  stored reference is the exact solution rounded to double precision, and `reference_low` the
  rounding error (the exact solution is `reference + reference_low` to about 1e-32, so errors
  near the double-precision rounding level are measured, not rounded away). The exact problem takes
  an unbounded revolute joint's angle, Pinocchio gets its rounded `(cos, sin)`;
- `pinocchio_local`, `pinocchio_world`: `pin.aba(model, data, q, v, tau)` with
  `Convention.LOCAL` (the default) and `Convention.WORLD`, and their errors against the reference.

Errors are the largest absolute difference over the largest reference entry of each sample. The
RNEA below is checked against `pin.rnea` (evaluated in double precision it must agree to 1e-13 on
every sample) before it is trusted.
"""

import gzip
import json
import os
import sys

import mpmath
import numpy as np
import pinocchio as pin

HERE = os.path.dirname(os.path.abspath(__file__))
SAMPLES = 20
SEED = 20261127
# Digits of the multiple-precision residuals.
DIGITS = 40
ITERATIONS = 8
# The largest last correction (relative to the largest entry) accepted from the refinement.
UNCERTAINTY = 1e-18


class Scalars:
    """The float type the recursive Newton-Euler algorithm below computes in."""

    def __init__(self, conv, cos, sin):
        self.conv, self.cos, self.sin = conv, cos, sin

    def array(self, x):
        return np.array([self.conv(float(e)) for e in np.asarray(x, dtype=float).reshape(-1)],
                        dtype=object if self.conv is mpmath.mpf else float).reshape(np.shape(x))


F64 = Scalars(float, np.cos, np.sin)
MP = Scalars(mpmath.mpf, mpmath.cos, mpmath.sin)

ROBOTS = [
    ("icub", "robots/icub_description/robots/icub.urdf.gz"),
    ("tiago_no_hand", "robots/tiago_description/robots/tiago_no_hand.urdf.gz"),
    ("human", "robots/human_description/robots/human.urdf.gz"),
]


def floats(x):
    return [float(v) for v in np.asarray(x, dtype=object).reshape(-1)]


def cross(a, b):
    return np.array([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]])


def axis_rotation(u, c, s):
    """Rotation by the angle of (cos, sin) = (c, s) about the unit axis u (Rodrigues)."""
    t = 1 - c
    x, y, z = u
    return np.array(
        [
            [c + t * x * x, t * x * y - s * z, t * x * z + s * y],
            [t * x * y + s * z, c + t * y * y, t * y * z - s * x],
            [t * x * z - s * y, t * y * z + s * x, c + t * z * z],
        ]
    )


def quat_rotation(x, y, z, w):
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


AXES = {"X": [1, 0, 0], "Y": [0, 1, 0], "Z": [0, 0, 1]}


class Tree:
    """The model's tree in the float type `sc`: per joint its parent, placement, kind, axis, the
    index of its first q and v entries, and its inertia about the joint origin."""

    def __init__(self, model, sc):
        self.sc = sc
        self.joints = []
        for j in range(1, model.njoints):
            jm = model.joints[j]
            name = jm.shortname()
            placement = model.jointPlacements[j]
            inertia = model.inertias[j]
            m = sc.conv(inertia.mass)
            c = sc.array(inertia.lever)
            ic = sc.array(inertia.inertia)
            rot = ic + m * (np.dot(c, c) * sc.array(np.eye(3)) - np.outer(c, c))
            if name == "JointModelFreeFlyer":
                kind, axis = "free", None
            elif name == "JointModelRevoluteUnaligned":
                kind, axis = "revolute", sc.array(jm.extract().axis)
            elif name.startswith("JointModelRUB"):
                kind, axis = "unbounded", sc.array(AXES[name[-1]])
            elif name.startswith("JointModelR"):
                kind, axis = "revolute", sc.array(AXES[name[-1]])
            elif name == "JointModelPrismaticUnaligned":
                kind, axis = "prismatic", sc.array(jm.extract().axis)
            elif name.startswith("JointModelP"):
                kind, axis = "prismatic", sc.array(AXES[name[-1]])
            else:
                sys.exit(f"joint type {name} is not handled")
            self.joints.append(
                {
                    "parent": model.parents[j] - 1,
                    "R": sc.array(placement.rotation),
                    "p": sc.array(placement.translation),
                    "kind": kind,
                    "axis": axis,
                    "iq": jm.idx_q,
                    "iv": jm.idx_v,
                    "m": m,
                    "h": m * c,
                    "I": rot,
                }
            )
        self.gravity = sc.array(model.gravity.linear)

    def rnea(self, q, v, a):
        """tau = RNEA(q, v, a) in joint frames, linear parts first (Featherstone table 5.1);
        q in Pinocchio's layout except that an unbounded revolute joint reads its angle at idx_q.
        q, v, a are arrays of this tree's float type."""
        sc = self.sc
        n = len(self.joints)
        vel, acc, frc, placements = [None] * n, [None] * n, [None] * n, [None] * n
        zero = sc.array(np.zeros(3))
        for i, j in enumerate(self.joints):
            iq, iv = j["iq"], j["iv"]
            if j["kind"] == "free":
                rj = quat_rotation(*q[iq + 3 : iq + 7])
                pj = q[iq : iq + 3]
                vj = (v[iv : iv + 3], v[iv + 3 : iv + 6])
                aj = (a[iv : iv + 3], a[iv + 3 : iv + 6])
            elif j["kind"] in ("revolute", "unbounded"):
                rj = axis_rotation(j["axis"], sc.cos(q[iq]), sc.sin(q[iq]))
                pj = zero
                vj = (zero, j["axis"] * v[iv])
                aj = (zero, j["axis"] * a[iv])
            else:
                rj = sc.array(np.eye(3))
                pj = j["axis"] * q[iq]
                vj = (j["axis"] * v[iv], zero)
                aj = (j["axis"] * a[iv], zero)
            r = j["R"] @ rj
            p = j["p"] + j["R"] @ pj
            placements[i] = (r, p)
            if j["parent"] < 0:
                pv, pw = zero, zero
                pa, pal = -self.gravity, zero
            else:
                (pv, pw), (pa, pal) = vel[j["parent"]], acc[j["parent"]]
            # Motion from the parent's frame to this one: (R^T (v - p x w), R^T w).
            w = r.T @ pw + vj[1]
            lin = r.T @ (pv - cross(p, pw)) + vj[0]
            al = r.T @ pal
            ac = r.T @ (pa - cross(p, pal))
            # + v x_m vJ = (w x vJ_lin + lin x vJ_ang, w x vJ_ang), + S a.
            ac = ac + cross(w, vj[0]) + cross(lin, vj[1]) + aj[0]
            al = al + cross(w, vj[1]) + aj[1]
            vel[i], acc[i] = (lin, w), (ac, al)
            m, h, inertia = j["m"], j["h"], j["I"]
            fa, na = m * ac - cross(h, al), inertia @ al + cross(h, ac)
            fv, nv = m * lin - cross(h, w), inertia @ w + cross(h, lin)
            # + v x_f (I v) = (w x fv, w x nv + lin x fv).
            frc[i] = [fa + cross(w, fv), na + cross(w, nv) + cross(lin, fv)]
        tau = sc.array(np.zeros(len(v)))
        for i in reversed(range(n)):
            j = self.joints[i]
            f, nn = frc[i]
            iv = j["iv"]
            if j["kind"] == "free":
                tau[iv : iv + 3] = f
                tau[iv + 3 : iv + 6] = nn
            elif j["kind"] in ("revolute", "unbounded"):
                tau[iv] = np.dot(j["axis"], nn)
            else:
                tau[iv] = np.dot(j["axis"], f)
            if j["parent"] >= 0:
                r, p = placements[i]
                rf = r @ f
                frc[j["parent"]][0] = frc[j["parent"]][0] + rf
                frc[j["parent"]][1] = frc[j["parent"]][1] + r @ nn + cross(p, rf)
        return tau


def sample(model, rng):
    """(q in anim-rigid's layout, q in Pinocchio's, q for the reference tree: Pinocchio's layout
    with an unbounded revolute joint's angle at its idx_q)."""
    ours, pinq, ref = [], np.zeros(model.nq), np.zeros(model.nq)
    for j in range(1, model.njoints):
        jm = model.joints[j]
        iq, name = jm.idx_q, jm.shortname()
        if name == "JointModelFreeFlyer":
            t = rng.uniform(-1.0, 1.0, 3)
            quat = rng.normal(size=4)
            quat /= np.linalg.norm(quat)
            vals = list(t) + list(quat)
            pinq[iq : iq + 7] = vals
            ref[iq : iq + 7] = vals
            ours += vals
        elif name.startswith("JointModelRUB"):
            theta = rng.uniform(-np.pi, np.pi)
            pinq[iq : iq + 2] = [np.cos(theta), np.sin(theta)]
            ref[iq] = theta
            ours.append(theta)
        else:
            lo, hi = model.lowerPositionLimit[iq], model.upperPositionLimit[iq]
            x = lo + (hi - lo) * rng.random()
            pinq[iq] = x
            ref[iq] = x
            ours.append(x)
    return np.array(ours), pinq, ref


def rel_err(x, ref):
    """Largest absolute difference over the largest reference entry, evaluated in `ref`'s type."""
    d = max(abs(MP.conv(float(a)) - b) for a, b in zip(np.asarray(x, dtype=float), ref))
    return float(d / max(abs(b) for b in ref))


def reference_solve(model, data, tree, q_pin, q_ref, v, tau):
    """H^-1 (tau - C) by a double-precision Cholesky solve refined with multiple-precision
    residuals; also cond(H) and the last correction over the largest entry."""
    h = pin.crba(model, data, q_pin).copy()
    h = np.triu(h) + np.triu(h, 1).T
    c = pin.nonLinearEffects(model, data, q_pin, v).copy()
    chol = np.linalg.cholesky(h)

    def solve(b):
        return np.linalg.solve(chol.T, np.linalg.solve(chol, np.asarray(b, dtype=float)))

    x = MP.array(solve(tau - c))
    q_mp, v_mp, tau_mp = MP.array(q_ref), MP.array(v), MP.array(tau)
    change = np.inf
    for _ in range(ITERATIONS):
        dx = solve(tau_mp - tree.rnea(q_mp, v_mp, x))
        x = x + MP.array(dx)
        change = float(np.max(np.abs(dx))) / float(max(abs(e) for e in x))
    if change > UNCERTAINTY:
        sys.exit(f"iterative refinement stalled: last correction {change:e} of the solution")
    return x, float(np.linalg.cond(h)), change


def main():
    mpmath.mp.dps = DIGITS
    rng = np.random.default_rng(SEED)
    out = {
        "generator": "crates/anim-rigid/testdata/make_pinocchio_aba_reference.py",
        "pinocchio_version": pin.__version__,
        "residual_digits": DIGITS,
        "models": [],
    }
    for name, urdf in ROBOTS:
        with gzip.open(os.path.join(HERE, urdf), "rt") as f:
            xml = f.read()
        for floating in (False, True):
            model = pin.buildModelFromXML(xml, pin.JointModelFreeFlyer()) if floating else pin.buildModelFromXML(xml)
            data = model.createData()
            tree_mp, tree_f64 = Tree(model, MP), Tree(model, F64)
            entry = {
                "name": name + ("_floating" if floating else ""),
                "urdf": urdf,
                "floating_base": floating,
                "nq_pinocchio": model.nq,
                "nv": model.nv,
                "joint_names": [model.names[j] for j in range(1, model.njoints)],
                "samples": [],
            }
            worst = {"local": 0.0, "world": 0.0, "cond": 0.0, "change": 0.0}
            for _ in range(SAMPLES):
                ours, q_pin, q_ref = sample(model, rng)
                v = rng.uniform(-2.0, 2.0, model.nv)
                a = rng.uniform(-3.0, 3.0, model.nv)
                tau = rng.uniform(-10.0, 10.0, model.nv)
                ours_f64 = tree_f64.rnea(q_ref, v, a)
                pin_f64 = pin.rnea(model, data, q_pin, v, a)
                check = float(np.max(np.abs(ours_f64 - pin_f64)) / np.max(np.abs(pin_f64)))
                if check > 1e-13:
                    sys.exit(f"{name}: the extended-precision RNEA disagrees with pin.rnea by {check:e}")
                ref, cond, change = reference_solve(model, data, tree_mp, q_pin, q_ref, v, tau)
                local = pin.aba(model, data, q_pin, v, tau).copy()
                world = pin.aba(model, data, q_pin, v, tau, pin.Convention.WORLD).copy()
                e_local, e_world = rel_err(local, ref), rel_err(world, ref)
                worst = {"local": max(worst["local"], e_local), "world": max(worst["world"], e_world),
                         "cond": max(worst["cond"], cond), "change": max(worst["change"], change)}
                entry["samples"].append(
                    {
                        "q": floats(ours), "q_pinocchio": floats(q_pin), "v": floats(v), "tau": floats(tau),
                        "reference": floats(ref),
                        "reference_low": [float(e - MP.conv(float(e))) for e in ref], "pinocchio_local": floats(local),
                        "pinocchio_world": floats(world), "pinocchio_local_error": e_local,
                        "pinocchio_world_error": e_world, "mass_matrix_condition": cond,
                        "reference_last_correction": change,
                    }
                )
            entry["pinocchio_local_error"] = worst["local"]
            entry["pinocchio_world_error"] = worst["world"]
            out["models"].append(entry)
            print(f"{entry['name']}: nv={model.nv}, cond(H) <= {worst['cond']:.2e}, "
                  f"last correction <= {worst['change']:.1e}, Pinocchio LOCAL {worst['local']:.2e}, WORLD {worst['world']:.2e}")
    target = os.path.join(HERE, "pinocchio_aba_accuracy.json")
    with open(target, "w") as f:
        json.dump(out, f, separators=(",", ":"))
        f.write("\n")
    print(f"wrote {target}")


if __name__ == "__main__":
    main()
