"""Grid fluids from anim-fluid (Stam's stable fluids, the MAC solver), fields as grid-shaped arrays."""

from typing import List, Optional

import numpy as np
import numpy.typing as npt

SCENES: List[str]

class Scene:
    def __init__(self, name: str, resolution: Optional[int] = None) -> None: ...
    def step(self, steps: int = 1, dt: Optional[float] = None) -> None: ...
    @property
    def dim(self) -> int: ...
    @property
    def time(self) -> float: ...
    @property
    def cell_size(self) -> float: ...
    def density(self) -> npt.NDArray[np.float64]:
        """(ny, nx) or (nz, ny, nx), a new array."""
    def velocity(self) -> npt.NDArray[np.float64]:
        """(ny, nx, 2) or (nz, ny, nx, 3) at the cell centres, a new array."""
