"""anim: physically based animation from Python.

The native module ``anim._anim`` is the Rust workspace's own library code (the crates' solvers,
the scene registry, the scene files of the ``anim`` command); this package re-exports it as

- ``anim.scene``: list the registered scene kinds and presets, build a preset or a scene file,
  step it, read its frames, checkpoint and resume, pick the cheapest method for a tolerance;
- ``anim.pbd``: PBD and XPBD cloth, ropes and soft bodies from numpy vertices and elements;
- ``anim.rigid``: URDF models, kinematics, Jacobians, RNEA, CRBA, ABA and IK, named as in
  Pinocchio.

Arrays come back as new numpy arrays (copies) of float64 (or int64 for indices); inputs are
checked (dtype, shape, contiguity, finiteness) and a bad one raises ``ValueError`` or
``TypeError`` naming the argument. The crates' own errors are ``anim.AnimError`` and its
subclasses; a missing file is ``FileNotFoundError``.
"""

import sys as _sys

from . import _anim
from ._anim import AnimError, BuildError, CheckpointError, SimulationError

__version__ = _anim.__version__

scene = _anim.scene
pbd = _anim.pbd
rigid = _anim.rigid
mpm = _anim.mpm
io = _anim.io
springs = _anim.springs
skin = _anim.skin
fem = _anim.fem
flip = _anim.flip
fluid = _anim.fluid

# `import anim.rigid` and `from anim.rigid import rnea` find the native submodules.
for _name in ("scene", "pbd", "rigid", "mpm", "io", "springs", "skin", "fem", "flip", "fluid"):
    _sys.modules[f"{__name__}.{_name}"] = getattr(_anim, _name)

__all__ = [
    "AnimError",
    "BuildError",
    "CheckpointError",
    "SimulationError",
    "fem",
    "flip",
    "fluid",
    "io",
    "mpm",
    "pbd",
    "rigid",
    "scene",
    "skin",
    "springs",
]
