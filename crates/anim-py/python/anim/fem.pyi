"""Tetrahedral FEM bodies from anim-fem (Sifakis & Barbič 2012), with per-element stresses."""

from typing import Literal, Optional, Sequence, Tuple

import numpy as np
import numpy.typing as npt

Material = Literal["linear", "st-venant-kirchhoff", "corotated-linear", "neo-hookean", "fixed-corotated", "stable-neo-hookean"]

def box_mesh(
    origin: npt.ArrayLike, size: npt.ArrayLike, cells: Tuple[int, int, int]
) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.int64]]: ...

class Simulation:
    def __init__(
        self,
        vertices: npt.ArrayLike,
        tets: npt.ArrayLike,
        *,
        young: float,
        poisson: float,
        density: float,
        material: Material = "stable-neo-hookean",
        gravity: Optional[npt.ArrayLike] = None,
        pins: Optional[Sequence[int]] = None,
        integrator: Literal["backward-euler", "symplectic-euler"] = "backward-euler",
    ) -> None: ...
    def step(self, dt: float, steps: int = 1) -> None: ...
    def solve_static(self, load_steps: int = 1) -> int: ...
    @property
    def positions(self) -> npt.NDArray[np.float64]: ...
    @positions.setter
    def positions(self, value: npt.ArrayLike) -> None: ...
    @property
    def velocities(self) -> npt.NDArray[np.float64]: ...
    @property
    def time(self) -> float: ...
    def stresses(self) -> npt.NDArray[np.float64]:
        """Cauchy stress per element, (m, 3, 3) (a new array)."""
    def first_piola(self) -> npt.NDArray[np.float64]:
        """First Piola-Kirchhoff stress per element, (m, 3, 3) (a new array)."""
