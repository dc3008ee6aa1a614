"""anim.fem: stresses of a homogeneous deformation against the closed-form models, a clamped
bar sagging under gravity, and bad input."""

import numpy as np
import pytest

import anim

E, NU = 1e6, 0.3
MU = E / (2 * (1 + NU))
LAM = E * NU / ((1 + NU) * (1 - 2 * NU))


def body(material):
    v, t = anim.fem.box_mesh([0, 0, 0], [1, 1, 1], [2, 2, 2])
    return v, t, anim.fem.Simulation(v, t, young=E, poisson=NU, density=1000.0, material=material)


F = np.array([[1.1, 0.05, 0.0], [0.02, 0.95, 0.03], [0.0, -0.04, 1.02]])


@pytest.mark.parametrize(
    "material, pk1",
    [
        ("linear", lambda F: MU * (F + F.T - 2 * np.eye(3)) + LAM * np.trace(F - np.eye(3)) * np.eye(3)),
        (
            "neo-hookean",
            lambda F: MU * (F - np.linalg.inv(F).T) + LAM * np.log(np.linalg.det(F)) * np.linalg.inv(F).T,
        ),
        (
            "st-venant-kirchhoff",
            lambda F: F @ (2 * MU * (0.5 * (F.T @ F - np.eye(3))) + LAM * np.trace(0.5 * (F.T @ F - np.eye(3))) * np.eye(3)),
        ),
    ],
)
def test_homogeneous_deformation_gives_the_models_stress_in_every_element(material, pk1):
    v, t, sim = body(material)
    sim.positions = v @ F.T
    P = sim.first_piola()
    assert P.shape == (len(t), 3, 3) and P.dtype == np.float64
    expected = pk1(F)
    np.testing.assert_allclose(P, np.broadcast_to(expected, P.shape), rtol=1e-9, atol=1e-6)
    sigma = sim.stresses()
    np.testing.assert_allclose(sigma[0], expected @ F.T / np.linalg.det(F), rtol=1e-9, atol=1e-6)


def test_clamped_bar_sags_and_rest_is_stress_free():
    v, t = anim.fem.box_mesh([0, 0, 0], [1.0, 0.1, 0.1], [10, 1, 1])
    clamp = np.flatnonzero(v[:, 0] == 0.0)
    sim = anim.fem.Simulation(v, t, young=1e7, poisson=0.3, density=1000.0, gravity=[0, 0, -9.81], pins=clamp)
    # At rest F = I up to rounding: every stress is zero to rounding of E.
    assert np.abs(sim.stresses()).max() <= 1e-14 * 1e7
    sim.step(1 / 60, steps=10)
    x = sim.positions
    np.testing.assert_array_equal(x[clamp], v[clamp])
    assert x[:, 2].min() < -1e-3
    assert sim.time == pytest.approx(10 / 60)


def test_fem_bad_input():
    v, t = anim.fem.box_mesh([0, 0, 0], [1, 1, 1], [1, 1, 1])
    with pytest.raises(ValueError, match="material"):
        anim.fem.Simulation(v, t, young=E, poisson=NU, density=1.0, material="rubber")
    with pytest.raises(anim.BuildError):
        anim.fem.Simulation(v, t, young=E, poisson=0.5, density=1.0)
    with pytest.raises(ValueError, match="tets"):
        anim.fem.Simulation(v, t + 100, young=E, poisson=NU, density=1.0)
    with pytest.raises(ValueError, match="pins"):
        anim.fem.Simulation(v, t, young=E, poisson=NU, density=1.0, pins=[99])
    inverted = t.copy()
    inverted[:, [0, 1]] = inverted[:, [1, 0]]
    with pytest.raises(anim.BuildError):
        anim.fem.Simulation(v, inverted, young=E, poisson=NU, density=1.0)
