"""Position based dynamics (PBD, Müller et al. 2007; XPBD, Macklin et al. 2016) from anim-pbd."""

from typing import Literal, Optional, Sequence, Union

import numpy as np
import numpy.typing as npt

ArrayLike = npt.ArrayLike

class Builder:
    """Collects particles, constraints, pins and colliders; gravity is zero until set."""

    def __init__(self, gravity: Optional[ArrayLike] = None) -> None: ...
    @property
    def num_particles(self) -> int: ...
    def triangle_mesh(
        self,
        vertices: ArrayLike,
        triangles: ArrayLike,
        *,
        mass: Optional[float] = None,
        density: Optional[float] = None,
        stretch_compliance: float = 0.0,
        stretch_stiffness: float = 1.0,
        bending: Literal["isometric", "dihedral", "none"] = "isometric",
        bending_compliance: float = 0.0,
        bending_stiffness: float = 1.0,
        damping: float = 0.0,
    ) -> int:
        """A cloth from (n, 3) float64 vertices and (m, 3) integer triangles; returns its first particle."""
    def tet_mesh(
        self,
        vertices: ArrayLike,
        tets: ArrayLike,
        *,
        mass: Optional[float] = None,
        density: Optional[float] = None,
        volume_compliance: float = 0.0,
        stretch_compliance: Optional[float] = None,
        damping: float = 0.0,
    ) -> int:
        """A soft body from (n, 3) float64 vertices and (m, 4) integer tetrahedra; returns its first particle."""
    def chain(
        self,
        count: int,
        start: ArrayLike,
        end: ArrayLike,
        *,
        mass: float,
        compliance: float = 0.0,
        stiffness: float = 1.0,
        damping: float = 0.0,
    ) -> int:
        """A rope of `count` particles from `start` to `end`; returns its first particle."""
    def pin(self, particles: Union[int, Sequence[int], ArrayLike]) -> None:
        """Pins particles (inverse mass 0)."""
    def sphere(self, center: ArrayLike, radius: float, *, thickness: float = 0.0, friction: float = 0.0) -> None:
        """A static sphere collider."""
    def ground(self, height: float = 0.0, *, friction: float = 0.0) -> None:
        """The ground plane z = height (anim-pbd is z up)."""
    def build(
        self,
        *,
        method: Literal["xpbd", "pbd"] = "xpbd",
        solver: Literal["gauss-seidel", "colored-gauss-seidel", "jacobi"] = "gauss-seidel",
        iterations: int = 10,
        substeps: int = 1,
    ) -> Simulation:
        """Checks the model and makes the simulation (raises anim.BuildError)."""

class Simulation:
    """A PBD or XPBD simulation and its state."""

    def step(self, dt: float, steps: int = 1) -> None:
        """Advances `steps` steps of `dt` s without the GIL (raises anim.SimulationError)."""
    @property
    def num_particles(self) -> int: ...
    @property
    def positions(self) -> npt.NDArray[np.float64]:
        """(n, 3) float64, a copy; assignable from an (n, 3) float64 array."""
    @positions.setter
    def positions(self, value: ArrayLike) -> None: ...
    @property
    def velocities(self) -> npt.NDArray[np.float64]:
        """(n, 3) float64, a copy; assignable."""
    @velocities.setter
    def velocities(self, value: ArrayLike) -> None: ...
    @property
    def triangles(self) -> npt.NDArray[np.int64]:
        """(m, 3) int64, a copy."""
    @property
    def steps(self) -> int: ...
    def max_violation(self) -> float:
        """The largest constraint violation at the current positions."""
