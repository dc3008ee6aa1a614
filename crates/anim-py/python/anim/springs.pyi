"""Mass-spring networks from anim-springs (z up), stepped by anim-core's integrators."""

from typing import Any, Mapping, Optional, Sequence, Union

import numpy as np
import numpy.typing as npt

class Builder:
    def __init__(self, gravity: Optional[npt.ArrayLike] = None) -> None: ...
    def mesh(
        self,
        vertices: npt.ArrayLike,
        triangles: npt.ArrayLike,
        *,
        stiffness: float,
        damping: float = 0.0,
        mass: Optional[float] = None,
        density: Optional[float] = None,
        bending_stiffness: Optional[float] = None,
        bending_damping: float = 0.0,
    ) -> int: ...
    def chain(
        self, count: int, start: npt.ArrayLike, end: npt.ArrayLike, *, mass: float, stiffness: float, damping: float = 0.0
    ) -> int: ...
    def pin(self, particles: Union[int, Sequence[int], npt.ArrayLike]) -> None: ...
    def ground(self, height: float, *, stiffness: float) -> None: ...
    def build(
        self, *, integrator: Optional[Union[str, Mapping[str, Any]]] = None, linear_solver: str = "cholesky"
    ) -> Simulation: ...

class Simulation:
    def step(self, dt: float, steps: int = 1) -> None: ...
    @property
    def positions(self) -> npt.NDArray[np.float64]: ...
    @property
    def velocities(self) -> npt.NDArray[np.float64]: ...
    @property
    def time(self) -> float: ...
    @property
    def num_particles(self) -> int: ...
