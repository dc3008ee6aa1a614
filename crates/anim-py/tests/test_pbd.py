"""anim.pbd: an XPBD cloth and a rope from numpy arrays, checked against closed forms."""

import numpy as np
import pytest

import anim


def grid(n, size=1.0, z=1.0):
    xs, ys = np.meshgrid(np.linspace(0, size, n), np.linspace(0, size, n))
    vertices = np.stack([xs.ravel(), ys.ravel(), np.full(n * n, z)], axis=1)
    tris = []
    for j in range(n - 1):
        for i in range(n - 1):
            a, b, c, d = j * n + i, j * n + i + 1, (j + 1) * n + i + 1, (j + 1) * n + i
            tris += [(a, b, c), (a, c, d)]
    return vertices, np.array(tris, dtype=np.int64)


def test_free_cloth_falls_as_a_rigid_body_under_gravity():
    # No pins, no colliders: the constraints hold the rest shape and the centre of mass falls
    # by g t^2 / 2 (semi-implicit Euler: g dt^2 (k (k + 1) / 2) after k steps).
    vertices, tris = grid(6)
    b = anim.pbd.Builder(gravity=[0.0, 0.0, -9.81])
    b.triangle_mesh(vertices, tris, mass=0.01, bending_compliance=1.0)
    sim = b.build(method="xpbd", iterations=5)
    dt, k = 1.0 / 60.0, 30
    sim.step(dt, steps=k)
    x = sim.positions
    assert x.shape == (36, 3) and x.dtype == np.float64
    drop = vertices[:, 2].mean() - x[:, 2].mean()
    assert drop == pytest.approx(9.81 * dt * dt * k * (k + 1) / 2, rel=1e-9)
    # The shape is unchanged (a rigid translation).
    assert np.allclose(x - x.mean(axis=0), vertices - vertices.mean(axis=0), atol=1e-9)


def test_pinned_cloth_hangs_and_pins_stay():
    n = 8
    vertices, tris = grid(n)
    b = anim.pbd.Builder(gravity=[0.0, 0.0, -9.81])
    b.triangle_mesh(vertices, tris, mass=0.01, bending="dihedral", bending_compliance=10.0)
    pins = [n * (n - 1), n * n - 1]
    b.pin(pins)
    sim = b.build(method="xpbd", solver="colored-gauss-seidel", iterations=20, substeps=2)
    edges = np.concatenate([tris[:, [0, 1]], tris[:, [1, 2]], tris[:, [2, 0]]])
    rest = np.linalg.norm(vertices[edges[:, 0]] - vertices[edges[:, 1]], axis=1)
    lowest = vertices[0, 2]
    for _ in range(6):
        sim.step(1 / 60, steps=20)
        x = sim.positions
        lowest = min(lowest, x[0, 2])
        # Rigid distance constraints (compliance 0): every edge within 2% of its rest length.
        length = np.linalg.norm(x[edges[:, 0]] - x[edges[:, 1]], axis=1)
        assert np.abs(length / rest - 1).max() < 0.02
        assert np.array_equal(x[pins], vertices[pins])
    # The free corner, 1 m from the pinned edge, swings down through most of that metre.
    assert lowest < vertices[0, 2] - 0.8
    assert sim.triangles.shape == tris.shape
    assert np.array_equal(sim.triangles, tris)
    assert sim.steps == 120


def test_positions_are_copies_and_setters_copy_in():
    vertices, tris = grid(3)
    b = anim.pbd.Builder()
    b.triangle_mesh(vertices, tris, mass=1.0)
    sim = b.build()
    x = sim.positions
    x[:] = 0.0
    assert np.array_equal(sim.positions, vertices)
    moved = vertices + [0.0, 0.0, 2.0]
    sim.positions = moved
    assert np.array_equal(sim.positions, moved)
    sim.velocities = np.ones((9, 3))
    sim.step(0.5)
    # No gravity, no stretch: everything moves by v dt.
    assert np.allclose(sim.positions, moved + 0.5, atol=1e-12)


def test_rope_hangs_still_from_its_pin_at_its_length():
    # A rope hanging straight down from its pin is at equilibrium: it stays on the vertical and
    # keeps its length (XPBD with compliance 0, converged by substeps).
    b = anim.pbd.Builder(gravity=[0, 0, -9.81])
    first = b.chain(11, [0, 0, 0], [0, 0, -1], mass=0.1)
    b.pin(first)
    sim = b.build(iterations=50, substeps=10)
    sim.step(1 / 60, steps=600)
    x = sim.positions
    assert np.abs(x[:, :2]).max() == 0.0
    seg = np.linalg.norm(np.diff(x, axis=0), axis=1)
    np.testing.assert_allclose(seg, 0.1, rtol=1e-4)
    assert x[-1, 2] == pytest.approx(-1.0, rel=1e-4)


def test_soft_body_from_tetrahedra_keeps_its_volume_on_the_ground():
    v = np.array([[0, 0, 0.5], [1, 0, 0.5], [0, 1, 0.5], [0, 0, 1.5]], dtype=float)
    t = np.array([[0, 1, 2, 3]])
    b = anim.pbd.Builder(gravity=[0, 0, -9.81])
    b.tet_mesh(v, t, density=100.0, stretch_compliance=0.0)
    b.ground(0.0)
    sim = b.build(iterations=20)
    sim.step(1 / 60, steps=120)
    x = sim.positions
    vol = abs(np.linalg.det(np.stack([x[1] - x[0], x[2] - x[0], x[3] - x[0]]))) / 6
    assert vol == pytest.approx(1 / 6, rel=1e-3)
    assert x[:, 2].min() > -1e-3
