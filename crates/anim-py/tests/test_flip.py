"""anim.flip: a free-falling blob gains exactly g dt; still water stays still."""

import numpy as np
import pytest

import anim

H = 1 / 32


def test_free_fall_blob_gains_g_dt():
    sim = anim.flip.Simulation([32, 32], H)
    xs = np.arange(0.3 + H / 4, 0.6, H / 2)
    blob = np.stack(np.meshgrid(xs, xs + 0.1), axis=-1).reshape(-1, 2)
    sim.add_particles(blob)
    dt = 1e-3
    sim.step(dt)
    v, x = sim.velocities, sim.positions
    assert v.shape == blob.shape and v.dtype == np.float64
    # No wall is reached and the pressure of a free-falling blob is zero: v = g dt, x += v dt.
    np.testing.assert_allclose(v, np.broadcast_to([0.0, -9.81 * dt], v.shape), atol=1e-15)
    np.testing.assert_allclose(x, blob + [0.0, -9.81 * dt * dt], atol=1e-15)
    assert sim.time == pytest.approx(dt)


def test_still_water_stays_still():
    sim = anim.flip.Simulation([32, 32], H)
    xs, ys = np.arange(H / 4, 1, H / 2), np.arange(H / 4, 0.5, H / 2)
    sim.add_particles(np.stack(np.meshgrid(xs, ys), axis=-1).reshape(-1, 2))
    sim.step(1 / 120, steps=60)
    assert np.abs(sim.velocities).max() < 1e-8
    assert sim.max_divergence() < 1e-6


def test_flip_bad_input():
    with pytest.raises(ValueError, match="cells"):
        anim.flip.Simulation([8], H)
    with pytest.raises(ValueError, match="tansfer"):
        anim.flip.Simulation([8, 8], H, params={"tansfer": "apic"})
    with pytest.raises(anim.BuildError):
        anim.flip.Simulation([8, 8], -1.0)
    sim = anim.flip.Simulation([8, 8, 8], 0.1)
    with pytest.raises(ValueError, match="positions"):
        sim.add_particles(np.zeros((3, 2)))
    with pytest.raises(ValueError, match="velocities"):
        sim.add_particles(np.full((3, 3), 0.4), velocities=np.full((3, 3), np.nan))
