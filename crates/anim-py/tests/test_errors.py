"""Bad input from Python raises a named exception and never crashes the interpreter."""

import os

import numpy as np
import pytest

import anim
from anim import pbd, rigid, scene

V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], dtype=np.float64)
T = np.array([[0, 1, 2]])


def mesh(vertices=V, triangles=T, **kw):
    b = pbd.Builder()
    kw.setdefault("mass", 1.0)
    b.triangle_mesh(vertices, triangles, **kw)
    return b


@pytest.mark.parametrize(
    "vertices, exc, words",
    [
        (np.zeros((3, 2)), ValueError, ["vertices", "shape", "(n, 3)"]),
        (np.zeros((3, 3), dtype=np.float32), TypeError, ["vertices", "float64", "float32"]),
        (np.zeros((3, 3), dtype=np.int64), TypeError, ["vertices", "float64"]),
        (np.array([[0, 0, 0], [1, np.nan, 0], [0, 1, 0]]), ValueError, ["vertices", "[1, 1]", "NaN", "finite"]),
        (np.array([[0, 0, 0], [1, np.inf, 0], [0, 1, 0]]), ValueError, ["vertices", "inf"]),
        (np.zeros((3, 6))[:, ::2], ValueError, ["vertices", "C-contiguous"]),
        ("abc", (TypeError, ValueError), ["vertices"]),
    ],
)
def test_bad_vertices(vertices, exc, words):
    with pytest.raises(exc) as e:
        mesh(vertices=vertices)
    for w in words:
        assert w in str(e.value), (w, str(e.value))


@pytest.mark.parametrize(
    "triangles, exc, words",
    [
        (np.array([[0, 1, 3]]), ValueError, ["triangles", "3", "outside 0..3"]),
        (np.array([[0, 1, -1]]), ValueError, ["triangles", "-1"]),
        (np.array([[0.0, 1.0, 2.0]]), TypeError, ["triangles", "integer"]),
        (np.array([0, 1, 2]), ValueError, ["triangles", "shape"]),
    ],
)
def test_bad_triangles(triangles, exc, words):
    with pytest.raises(exc) as e:
        mesh(triangles=triangles)
    for w in words:
        assert w in str(e.value)


def test_crate_refusals_are_anim_errors():
    with pytest.raises(anim.BuildError):
        mesh(mass=-1.0)
    with pytest.raises(anim.BuildError):
        # A degenerate triangle (three points on a line).
        mesh(vertices=np.array([[0, 0, 0], [1, 0, 0], [2, 0, 0]], dtype=float))
    with pytest.raises(ValueError, match="mass, density"):
        pbd.Builder().triangle_mesh(V, T)
    with pytest.raises(ValueError, match="method"):
        mesh().build(method="verlet")
    with pytest.raises(ValueError, match="bending"):
        mesh(bending="cubic")
    with pytest.raises(ValueError, match="particles"):
        mesh().pin(7)
    sim = mesh().build()
    with pytest.raises(ValueError, match="dt"):
        sim.step(-1.0)
    with pytest.raises(ValueError, match="dt"):
        sim.step(float("nan"))
    with pytest.raises(ValueError, match="positions"):
        sim.positions = np.zeros((2, 3))
    assert issubclass(anim.BuildError, anim.AnimError)


def test_rigid_bad_input(tmp_path, rigid_data):
    with pytest.raises(FileNotFoundError, match="no-such.urdf"):
        rigid.build_model_from_urdf(str(tmp_path / "no-such.urdf"))
    with pytest.raises(anim.BuildError, match="XML|xml"):
        rigid.build_model_from_xml("<robot name='x'><link name='a'></robot>")
    model = rigid.build_model_from_urdf(
        os.path.join(rigid_data, "panda.urdf"), locked_joints=["panda_finger_joint1", "panda_finger_joint2"]
    )
    data = model.create_data()
    q = rigid.neutral(model)
    z = np.zeros(model.nv)
    with pytest.raises(ValueError, match="q"):
        rigid.rnea(model, data, q[:3], z, z)
    bad = q.copy()
    bad[2] = np.nan
    with pytest.raises(ValueError, match="q"):
        rigid.rnea(model, data, bad, z, z)
    with pytest.raises(ValueError, match="tau"):
        rigid.aba(model, data, q, z, np.zeros(2))
    with pytest.raises(TypeError, match="v"):
        rigid.rnea(model, data, q, z.astype(np.float32), z)
    with pytest.raises(ValueError, match="C-contiguous"):
        rigid.crba(model, data, np.zeros(2 * model.nq)[::2])
    other = rigid.build_model_from_xml(
        "<robot name='p'><link name='a'/><link name='b'><inertial><mass value='1'/>"
        "<inertia ixx='1' ixy='0' ixz='0' iyy='1' iyz='0' izz='1'/></inertial></link>"
        "<joint name='j' type='continuous'><parent link='a'/><child link='b'/><axis xyz='0 0 1'/></joint></robot>"
    )
    with pytest.raises(ValueError, match="data"):
        rigid.rnea(other, data, [0.0], [0.0], [0.0])
    rigid.compute_joint_jacobians(model, data, q)
    with pytest.raises(ValueError, match="reference_frame"):
        rigid.get_frame_jacobian(model, data, 1, "body")
    with pytest.raises(ValueError, match="frame"):
        rigid.get_frame_jacobian(model, data, 10_000, "world")
    with pytest.raises(ValueError, match="frame_id"):
        rigid.frame_placement(model, data, 10_000)
    with pytest.raises(ValueError, match="name"):
        model.get_frame_id("no-such-frame")
    with pytest.raises(ValueError, match="target"):
        rigid.inverse_kinematics(model, 1, np.full((4, 4), 2.0))
    with pytest.raises(ValueError, match="target"):
        rigid.inverse_kinematics(model, 1, np.eye(3))
    with pytest.raises(ValueError, match="q"):
        rigid.rnea_batch(model, data, np.zeros((2, 3)), np.zeros((2, 7)), np.zeros((2, 7)))


def test_scene_bad_input(tmp_path):
    with pytest.raises(ValueError, match="no preset"):
        scene.Scene.preset("no-such-scene")
    with pytest.raises(FileNotFoundError, match="missing.toml"):
        scene.Scene.from_file(str(tmp_path / "missing.toml"))
    with pytest.raises(anim.BuildError, match="kind"):
        scene.Scene.from_toml('name = "x"\n[run]\ndt = 0.1\nframes = 1\n[scene]\nkind = "nope"\n')
    with pytest.raises(anim.BuildError):
        scene.Scene.from_toml("this is not toml [")
    with pytest.raises(anim.BuildError, match="no_such_param"):
        scene.Scene.preset("oscillator", set={"no_such_param": 1})
    with pytest.raises(ValueError, match="tolerance"):
        scene.Scene.preset("oscillator", tolerance=-1.0)
    with pytest.raises(anim.BuildError):
        # A scene no study measured.
        scene.Scene.preset("pbd-rope", tolerance=1e-3)
    with pytest.raises(FileNotFoundError):
        scene.Scene.resume(str(tmp_path / "none.anim"))
    junk = tmp_path / "junk.anim"
    junk.write_bytes(b"not a checkpoint")
    with pytest.raises(anim.CheckpointError):
        scene.Scene.resume(str(junk))
    s = scene.Scene.preset("oscillator")
    with pytest.raises(ValueError, match="saved"):
        s.restore("{")
    with pytest.raises(anim.CheckpointError):
        s.restore('{"version": 999}')
    with pytest.raises(ValueError, match="dt"):
        s.step(1, dt=0.0)
