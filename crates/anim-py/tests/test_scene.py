"""anim.scene: the registry, presets, scene files, frames, checkpoints and the tolerance pick."""

import numpy as np
import pytest

import anim
from anim import scene

OSCILLATOR = """
name = "osc"
[run]
dt = 0.01
frames = 20
steps_per_frame = 5
[scene]
kind = "harmonic-oscillator"
mass = 1.0
stiffness = 40.0
damping = 0.2
x0 = 1.0
v0 = 0.0
integrator = "implicit-midpoint"
"""


def test_kinds_and_presets_list_the_registry():
    kinds = scene.kinds()
    names = {k["kind"] for k in kinds}
    assert {"springs", "pbd", "harmonic-oscillator", "fluid", "mpm"} <= names
    presets = scene.presets()
    assert {p["name"] for p in presets} == {n for k in kinds for n in k["presets"]}
    for p in presets:
        assert p["dt"] > 0 and p["frames"] >= 1 and p["steps_per_frame"] >= 1
    assert any(k["tolerance"] for k in kinds)


def test_oscillator_preset_steps_and_matches_its_exact_solution():
    s = scene.Scene.preset("oscillator")
    assert s.kind == "harmonic-oscillator"
    s.advance_frames(s.frames)
    assert s.time == pytest.approx(s.frames * s.steps_per_frame * s.dt, rel=1e-12)
    f = s.frame()
    assert f["time"] == s.time
    assert f["points"].shape[0] == 1 and f["points"].dtype == np.float64
    err = s.reference_error()
    assert err is not None and 0.0 <= err < 0.05


def test_checkpoint_and_resume_continue_bit_for_bit(tmp_path):
    s = scene.Scene.preset("pbd-cloth")
    s.step(5)
    path = tmp_path / "cloth.anim"
    s.checkpoint(str(path))
    s.step(5)
    after = s.frame()["points"]
    r = scene.Scene.resume(str(path))
    assert r.time == pytest.approx(5 * s.dt, rel=1e-12)
    r.step(5)
    assert np.array_equal(r.frame()["points"], after)
    # save / restore in memory.
    saved = r.save()
    r.step(3)
    r.restore(saved)
    r.step(3)
    s.step(3)
    assert np.array_equal(r.frame()["points"], s.frame()["points"])


def test_scene_from_toml_and_set_override():
    s = scene.Scene.from_toml(OSCILLATOR)
    assert (s.name, s.dt, s.frames, s.steps_per_frame) == ("osc", 0.01, 20, 5)
    s.step(100)
    assert s.time == pytest.approx(1.0)
    t = scene.Scene.from_toml(OSCILLATOR, set={"integrator": "rk4"})
    assert '"rk4"' in t.params
    t.step(100)
    assert t.reference_error() < s.reference_error()


def test_tolerance_picks_a_method_that_reaches_it():
    tol = 1e-3
    s = scene.Scene.preset("oscillator", tolerance=tol)
    c = s.choice
    assert c is not None and c["method"] and c["dt"] > 0
    assert s.dt == pytest.approx(c["dt"]) and s.steps_per_frame == c["steps_per_frame"]
    s.advance_frames(s.frames)
    assert s.reference_error() <= tol
    assert scene.Scene.preset("oscillator").choice is None


def test_grid_scene_fields_come_as_2d_arrays():
    s = scene.Scene.preset("smoke-box-2d", set={"resolution": 16})
    s.step(2)
    ctx = s.context()
    img = ctx["image"]
    assert img is not None and img["dim"] == 2
    nx, ny = img["dims"][0], img["dims"][1]
    fields = s.frame()["fields"]
    assert fields, "a grid scene has fields"
    for name, values in fields.items():
        assert values.shape[:2] == (ny, nx), name
        assert values.dtype == np.float64
