"""anim.mpm particles in and out; anim.io meshes written and read back."""

import numpy as np
import pytest

import anim


def test_free_fall_of_a_fluid_block_matches_gravity():
    # One step of MLS-MPM on a block far from the walls: every particle gets g dt (the grid
    # update adds gravity to a velocity field that was zero; a rest block has no pressure).
    sim = anim.mpm.Simulation(2, [{"fluid": {}}], params={"resolution": 32})
    g = np.stack(np.meshgrid(np.linspace(0.4, 0.6, 20), np.linspace(0.5, 0.7, 20)), axis=-1).reshape(-1, 2)
    first = sim.add_particles(g, mass=1e-4, volume=1e-4, material=0)
    assert first == 0 and sim.num_particles == 400
    x0 = sim.positions
    assert x0.shape == (400, 2) and x0.dtype == np.float32
    np.testing.assert_allclose(x0, g, atol=1e-7)
    dt = 1e-4
    sim.step(1, dt=dt)
    v = sim.velocities
    # Interior particles: exactly -g dt (edges see the fluid's pressure from the free surface).
    inner = (np.abs(g[:, 0] - 0.5) < 0.05) & (np.abs(g[:, 1] - 0.6) < 0.05)
    np.testing.assert_allclose(v[inner, 1], -9.81 * dt, rtol=1e-3)
    m, p, _ = sim.totals()
    assert m == pytest.approx(400 * 1e-4, rel=1e-6)
    assert p[1] == pytest.approx(-m * 9.81 * dt, rel=1e-3)


def test_builtin_scene_and_material_ids():
    sim = anim.mpm.Simulation.scene("three-materials", 32)
    n = sim.num_particles
    sim.step(3)
    assert sim.positions.shape == (n, 2)
    assert set(np.unique(sim.materials)) == {0, 1, 2}
    assert np.all(np.isfinite(sim.positions))


def test_mpm_bad_input():
    with pytest.raises(ValueError, match="dim"):
        anim.mpm.Simulation(4, [{"fluid": {}}])
    with pytest.raises(ValueError, match="materials"):
        anim.mpm.Simulation(2, [{"plasma": {}}])
    with pytest.raises(ValueError, match="resolutoin"):
        anim.mpm.Simulation(2, [{"fluid": {}}], params={"resolutoin": 32})
    sim = anim.mpm.Simulation(3, [{"fluid": {}}])
    with pytest.raises(ValueError, match="positions"):
        sim.add_particles(np.zeros((4, 2)), mass=1.0, volume=1.0)
    with pytest.raises(ValueError, match="mass"):
        sim.add_particles(np.full((4, 3), 0.5), mass=-1.0, volume=1.0)
    with pytest.raises(ValueError, match="material"):
        sim.add_particles(np.full((4, 3), 0.5), mass=1.0, volume=1.0, material=3)
    assert sim.num_particles == 0
    with pytest.raises(ValueError, match="name"):
        anim.mpm.Simulation.scene("no-such")


def test_meshes_round_trip_through_obj(tmp_path):
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=float)
    t = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    path = tmp_path / "tet.obj"
    anim.io.write_obj(str(path), v, t)
    v2, t2 = anim.io.read_tri_mesh(str(path))
    assert v2.dtype == np.float64 and t2.dtype == np.int64
    np.testing.assert_array_equal(v2, v)
    np.testing.assert_array_equal(t2, t)
    anim.io.write_ply(str(tmp_path / "tet.ply"), v, t)
    anim.io.write_vtu(str(tmp_path / "tet.vtu"), v, tets=[[0, 1, 2, 3]])
    assert (tmp_path / "tet.ply").stat().st_size > 0
    assert b"UnstructuredGrid" in (tmp_path / "tet.vtu").read_bytes()


def test_io_errors(tmp_path):
    with pytest.raises(FileNotFoundError):
        anim.io.read_tri_mesh(str(tmp_path / "none.obj"))
    bad = tmp_path / "bad.obj"
    bad.write_text("v 0 0 0\nv 1 0 0\nf 1 2 7\n")
    with pytest.raises(anim.BuildError, match="bad.obj"):
        anim.io.read_tri_mesh(str(bad))
    with pytest.raises(anim.BuildError, match="extension"):
        anim.io.read_tet_mesh(str(tmp_path / "mesh.stl"))
    with pytest.raises(ValueError, match="triangles"):
        anim.io.write_obj(str(tmp_path / "x.obj"), np.zeros((3, 3)), [[0, 1, 5]])
