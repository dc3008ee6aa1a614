"""anim.rigid against Pinocchio 4.1.0's values stored in crates/anim-rigid/testdata, and a
one-link pendulum in closed form."""

import json
import math
import os

import numpy as np
import pytest

import anim
from anim import rigid

PENDULUM = """<robot name="pendulum">
  <link name="base"/>
  <link name="bob">
    <inertial><origin xyz="0 0 -{l}"/><mass value="{m}"/>
      <inertia ixx="{i}" ixy="0" ixz="0" iyy="{i}" iyz="0" izz="{i}"/></inertial>
  </link>
  <joint name="hinge" type="revolute">
    <parent link="base"/><child link="bob"/><axis xyz="1 0 0"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/>
  </joint>
</robot>"""


def test_pendulum_rnea_crba_aba_in_closed_form():
    m, l, g, i = 2.0, 0.7, 9.81, 0.05
    model = rigid.build_model_from_xml(PENDULUM.format(m=m, l=l, i=i))
    data = model.create_data()
    assert (model.nq, model.nv) == (1, 1)
    q, v, a = np.array([0.4]), np.array([1.3]), np.array([-0.8])
    # tau = (m l^2 + I) a + m g l sin(q) for a body hanging at -l z (inertia I about its centre),
    # turning about x.
    tau = rigid.rnea(model, data, q, v, a)
    assert tau.shape == (1,) and tau.dtype == np.float64
    assert tau[0] == pytest.approx((m * l * l + i) * a[0] + m * g * l * math.sin(q[0]), rel=1e-12)
    assert rigid.crba(model, data, q)[0, 0] == pytest.approx(m * l * l + i, rel=1e-12)
    ddq = rigid.aba(model, data, q, v, np.array([0.0]))
    assert ddq[0] == pytest.approx(-m * g * l * math.sin(q[0]) / (m * l * l + i), rel=1e-12)


def load(rigid_data, name):
    with open(os.path.join(rigid_data, name)) as f:
        return json.load(f)


def test_panda_dynamics_match_pinocchio(rigid_data):
    ref = load(rigid_data, "pinocchio_dynamics_panda.json")
    model = rigid.build_model_from_urdf(
        os.path.join(rigid_data, ref["urdf"]), locked_joints=ref["locked_joints"]
    )
    data = rigid.Data(model)
    assert (model.nq, model.nv) == (ref["nq"], ref["nv"])
    n = model.nv
    for s in ref["samples"][:10]:
        q, v, a, tau = (np.array(s[k]) for k in ("q", "v", "a", "tau"))
        np.testing.assert_allclose(rigid.rnea(model, data, q, v, a), s["rnea"], rtol=0, atol=1e-9)
        np.testing.assert_allclose(rigid.crba(model, data, q), np.reshape(s["crba"], (n, n)), atol=1e-10)
        np.testing.assert_allclose(rigid.aba(model, data, q, v, tau), s["aba"], atol=1e-8)
        np.testing.assert_allclose(rigid.nonlinear_effects(model, data, q, v), s["nle"], atol=1e-9)
        np.testing.assert_allclose(rigid.compute_generalized_gravity(model, data, q), s["gravity"], atol=1e-9)
    # The batch form gives the same rows.
    rows = ref["samples"][:5]
    Q, V, A = (np.array([s[k] for s in rows]) for k in ("q", "v", "a"))
    np.testing.assert_allclose(rigid.rnea_batch(model, data, Q, V, A), [s["rnea"] for s in rows], atol=1e-9)


def se3(flat):
    m = np.eye(4)
    m[:3, :3] = np.reshape(flat[:9], (3, 3))
    m[:3, 3] = flat[9:]
    return m


def test_panda_kinematics_and_jacobians_match_pinocchio(rigid_data):
    ref = load(rigid_data, "pinocchio_panda.json")
    model = rigid.build_model_from_urdf(
        os.path.join(rigid_data, ref["urdf"]), locked_joints=ref["locked_joints"]
    )
    data = model.create_data()
    assert model.frame_names == [f["name"] for f in ref["frames"]]
    for s in ref["samples"][:5]:
        q = np.array(s["q"])
        rigid.frames_forward_kinematics(model, data, q)
        oMf = data.oMf
        assert oMf.shape == (model.nframes, 4, 4)
        for f, flat in enumerate(s["frame_placements"]):
            np.testing.assert_allclose(oMf[f], se3(flat), atol=1e-12)
        tool = model.get_frame_id(ref["tool_frames"][0])
        np.testing.assert_allclose(rigid.frame_placement(model, data, tool), se3(s["frame_placements"][tool]), atol=1e-12)
        R, p = rigid.frame_rotation_translation(model, data, tool)
        np.testing.assert_allclose(R, se3(s["frame_placements"][tool])[:3, :3], atol=1e-12)
        np.testing.assert_allclose(p, s["frame_placements"][tool][9:], atol=1e-12)
        rigid.compute_joint_jacobians(model, data, q)
        for name, by_rf in s["jacobians"].items():
            fid = model.get_frame_id(name)
            for rf, flat in by_rf.items():
                J = rigid.get_frame_jacobian(model, data, fid, rf.lower())
                assert J.shape == (6, model.nv)
                np.testing.assert_allclose(J, np.reshape(flat, (6, model.nv)), atol=1e-12, err_msg=f"{name} {rf}")


def test_configuration_helpers():
    xml = PENDULUM.format(m=1.0, l=1.0, i=0.1).replace('type="revolute"', 'type="continuous"')
    model = rigid.build_model_from_xml(xml)
    assert model.nq == 1 and rigid.pinocchio_nq(model) == 2
    q = np.array([2.5])
    qp = rigid.to_pinocchio(model, q)
    np.testing.assert_allclose(qp, [math.cos(2.5), math.sin(2.5)], atol=1e-15)
    np.testing.assert_allclose(rigid.from_pinocchio(model, qp), q, atol=1e-15)
    np.testing.assert_allclose(rigid.neutral(model), [0.0])
    v = np.array([0.3])
    np.testing.assert_allclose(rigid.integrate(model, q, v), q + v, atol=1e-15)
    np.testing.assert_allclose(rigid.difference(model, q, q + v), v, atol=1e-15)


def test_random_configuration_is_within_limits_and_reproducible(rigid_data):
    model = rigid.build_model_from_urdf(os.path.join(rigid_data, "panda.urdf"), locked_joints=["panda_finger_joint1", "panda_finger_joint2"])
    q1 = rigid.random_configuration(model, seed=3)
    assert np.array_equal(q1, rigid.random_configuration(model, seed=3))
    assert not np.array_equal(q1, rigid.random_configuration(model, seed=4))
    assert np.all(q1 >= model.lower_position_limit) and np.all(q1 <= model.upper_position_limit)


def test_inverse_kinematics_reaches_a_reachable_placement(rigid_data):
    model = rigid.build_model_from_urdf(os.path.join(rigid_data, "panda.urdf"), locked_joints=["panda_finger_joint1", "panda_finger_joint2"])
    data = model.create_data()
    tool = model.get_frame_id("panda_hand_tcp")
    q_goal = rigid.random_configuration(model, seed=11)
    rigid.frames_forward_kinematics(model, data, q_goal)
    target = rigid.frame_placement(model, data, tool)
    out = rigid.inverse_kinematics(model, tool, target)
    assert out["success"], out
    rigid.frames_forward_kinematics(model, data, out["q"])
    np.testing.assert_allclose(rigid.frame_placement(model, data, tool), target, atol=1e-8)
