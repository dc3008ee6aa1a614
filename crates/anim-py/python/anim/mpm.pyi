"""Material point method (APIC, MLS-MPM) from anim-mpm, 2D and 3D, particles in float32."""

from typing import Any, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

SCENES: List[str]

class Simulation:
    """An MPM simulation and its particles."""

    def __init__(self, dim: int, materials: Sequence[Mapping[str, Any]], params: Optional[Mapping[str, Any]] = None) -> None:
        """`materials` in the scene-file form ({"fluid": {"bulk": 1e5}}); `params` over MpmParams' defaults."""
    @staticmethod
    def scene(name: str, resolution: Optional[int] = None) -> Simulation:
        """A built-in scene of anim-mpm (see SCENES)."""
    def add_particles(
        self,
        positions: npt.ArrayLike,
        *,
        mass: Union[float, npt.ArrayLike],
        volume: Union[float, npt.ArrayLike],
        material: int = 0,
        velocities: Optional[npt.ArrayLike] = None,
    ) -> int: ...
    def step(self, steps: int = 1, dt: Optional[float] = None) -> None:
        """Advances without the GIL (raises anim.SimulationError)."""
    @property
    def dim(self) -> int: ...
    @property
    def num_particles(self) -> int: ...
    @property
    def dt(self) -> float: ...
    @property
    def time(self) -> float: ...
    @property
    def positions(self) -> npt.NDArray[np.float32]:
        """(n, dim) float32 in the order added (copy)."""
    @property
    def velocities(self) -> npt.NDArray[np.float32]: ...
    @property
    def materials(self) -> npt.NDArray[np.int64]: ...
    def totals(self) -> Tuple[float, List[float], List[float]]:
        """(mass, linear momentum, angular momentum)."""
