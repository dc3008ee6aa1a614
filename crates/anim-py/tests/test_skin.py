"""anim.skin on the glTF sample SimpleSkin: the rest pose is the file's positions (decoded here
from the buffer), LBS and DQS agree where the skeleton does not bend."""

import base64
import json
import os

import numpy as np
import pytest

import anim

HERE = os.path.dirname(os.path.abspath(__file__))
SIMPLE = os.path.join(HERE, "..", "..", "anim-skin", "testdata", "SimpleSkin.gltf")


def file_positions():
    with open(SIMPLE) as f:
        d = json.load(f)
    acc = d["accessors"][d["meshes"][0]["primitives"][0]["attributes"]["POSITION"]]
    view = d["bufferViews"][acc["bufferView"]]
    raw = base64.b64decode(d["buffers"][view["buffer"]]["uri"].split(",", 1)[1])
    start = view.get("byteOffset", 0) + acc.get("byteOffset", 0)
    return np.frombuffer(raw, dtype="<f4", count=3 * acc["count"], offset=start).reshape(-1, 3).astype(np.float64)


def test_rest_pose_is_the_files_positions_and_clips_move_the_top():
    c = anim.skin.Character.load(SIMPLE)
    assert c.num_vertices == 10 and c.num_joints >= 2
    rest = c.pose()
    np.testing.assert_allclose(rest, file_positions(), atol=1e-12)
    np.testing.assert_allclose(c.pose(method="dqs"), rest, atol=1e-12)
    assert len(c.clips) == 1 and c.clip_end(0) > 0
    t = 1.0  # the clip's second key: the upper joint turned a quarter turn
    lbs, dqs = c.pose(0, t, "lbs"), c.pose(c.clips[0], t, "dqs")
    assert lbs.shape == (10, 3) and lbs.dtype == np.float64
    # The bottom row is bound to the root joint alone, which the clip does not move.
    bottom = rest[:, 1] == 0.0
    np.testing.assert_allclose(lbs[bottom], rest[bottom], atol=1e-12)
    np.testing.assert_allclose(dqs[bottom], rest[bottom], atol=1e-12)
    # The top row turns with the second joint.
    top = rest[:, 1] == 2.0
    assert np.abs(lbs[top] - rest[top]).max() > 0.1
    # Bound to the upper joint alone (at y = 1): a rigid turn about it, the same for both methods.
    pivot = np.array([0.0, 1.0, 0.0])
    np.testing.assert_allclose(np.linalg.norm(lbs[top] - pivot, axis=1), np.linalg.norm(rest[top] - pivot, axis=1), rtol=1e-12)
    np.testing.assert_allclose(dqs[top], lbs[top], atol=1e-12)
    assert c.triangles.shape == (8, 3)


def test_skin_bad_input(tmp_path):
    with pytest.raises(FileNotFoundError):
        anim.skin.Character.load(str(tmp_path / "none.gltf"))
    bad = tmp_path / "bad.gltf"
    bad.write_text("{ not json")
    with pytest.raises(anim.BuildError):
        anim.skin.Character.load(str(bad))
    c = anim.skin.Character.load(SIMPLE)
    with pytest.raises(ValueError, match="clip"):
        c.pose(5, 0.0)
    with pytest.raises(ValueError, match="clip"):
        c.pose("walk", 0.0)
    with pytest.raises(ValueError, match="method"):
        c.pose(0, 0.0, "cubic")
    with pytest.raises(ValueError, match="t"):
        c.pose(0, float("nan"))
