"""anim.springs: a hanging spring settles at the static stretch m g / k; a mesh from numpy."""

import numpy as np
import pytest

import anim


def test_hanging_spring_settles_at_the_static_stretch():
    m, k, g = 0.5, 100.0, 9.81
    b = anim.springs.Builder(gravity=[0, 0, -g])
    b.chain(2, [0, 0, 0], [0, 0, -1], mass=m, stiffness=k, damping=5.0)
    b.pin(0)
    sim = b.build(integrator="backward-euler", linear_solver="cholesky")
    sim.step(0.01, steps=2000)
    x = sim.positions
    assert x.shape == (2, 3) and x.dtype == np.float64
    assert x[1, 2] == pytest.approx(-1.0 - m * g / k, abs=1e-9)
    assert sim.time == pytest.approx(20.0)


def test_spring_mesh_from_numpy_and_integrator_names():
    v = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], dtype=float)
    t = np.array([[0, 1, 2], [0, 2, 3]])
    b = anim.springs.Builder(gravity=[0, 0, -9.81])
    b.mesh(v, t, stiffness=1e3, damping=1.0, density=0.2, bending_stiffness=1.0)
    b.pin([0, 1])
    sim = b.build(integrator={"beta-blend": {"beta": 0.5}})
    sim.step(1e-3, steps=100)
    x = sim.positions
    np.testing.assert_array_equal(x[[0, 1]], v[[0, 1]])
    assert x[2, 2] < 0.0
    with pytest.raises(ValueError, match="integrator"):
        b.build(integrator="leapfrogg")
    with pytest.raises(ValueError, match="mass, density"):
        b.mesh(v, t, stiffness=1.0)
    with pytest.raises(anim.BuildError):
        b.mesh(v, t, stiffness=1.0, mass=-2.0)
