"""anim.fluid: grid-shaped fields; the lid-driven cavity turns clockwise under its lid."""

import numpy as np
import pytest

import anim


def test_cavity_fields_are_grid_shaped_and_the_lid_drives_a_vortex():
    s = anim.fluid.Scene("lid-driven-cavity", 16)
    s.step(200)
    v = s.velocity()
    assert v.shape == (16, 16, 2) and v.dtype == np.float64
    assert s.density().shape == (16, 16)
    u = v[..., 0]
    # The lid (top, y up) drags the fluid in +x under it; the return flow runs in -x below.
    assert u[-1].mean() > 0.1
    assert u[: 16 // 2].mean() < 0.0
    assert s.time > 0.0


def test_smoke_density_moves_and_3d_fields():
    s = anim.fluid.Scene("smoke-box-2d", 16)
    s.step(5)
    assert s.density().sum() > 0.0
    p = anim.fluid.Scene("smoke-plume-3d", 8)
    p.step(1)
    assert p.velocity().shape[-1] == 3 and p.velocity().ndim == 4
    with pytest.raises(ValueError, match="name"):
        anim.fluid.Scene("waves")
    with pytest.raises(ValueError, match="dt"):
        s.step(1, dt=-1.0)
