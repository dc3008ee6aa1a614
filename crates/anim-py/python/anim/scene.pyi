"""The scene registry: kinds, presets, scene files, frames, checkpoints, the tolerance pick."""

from typing import Any, Dict, List, Mapping, Optional, TypedDict

import numpy as np
import numpy.typing as npt

class KindInfo(TypedDict):
    kind: str
    crate: str
    summary: str
    presets: List[str]
    tolerance: bool

class PresetInfo(TypedDict):
    name: str
    kind: str
    description: str
    dt: float
    frames: int
    steps_per_frame: int

class FrameDict(TypedDict):
    time: float
    points: npt.NDArray[np.float64]
    fields: Dict[str, npt.NDArray[np.float64]]

def kinds() -> List[KindInfo]: ...
def presets() -> List[PresetInfo]: ...

class Scene:
    """A built scene of a registered kind."""

    @staticmethod
    def preset(name: str, *, set: Optional[Mapping[str, Any]] = None, tolerance: Optional[float] = None) -> Scene: ...
    @staticmethod
    def from_file(path: str, *, set: Optional[Mapping[str, Any]] = None, tolerance: Optional[float] = None) -> Scene: ...
    @staticmethod
    def from_toml(
        text: str,
        *,
        base: Optional[str] = None,
        set: Optional[Mapping[str, Any]] = None,
        tolerance: Optional[float] = None,
    ) -> Scene: ...
    @staticmethod
    def resume(path: str) -> Scene:
        """Continues a checkpoint of Scene.checkpoint or `anim run --checkpoint-every`."""
    def checkpoint(self, path: str) -> None: ...
    def save(self) -> str: ...
    def restore(self, saved: str) -> None: ...
    def step(self, steps: int = 1, dt: Optional[float] = None) -> None:
        """Advances without the GIL (raises anim.SimulationError)."""
    def advance_frames(self, frames: int = 1) -> None: ...
    def frame(self) -> FrameDict:
        """Points (n, point_dim) and fields; grid fields (ny, nx) or (nz, ny, nx). Copies."""
    def context(self) -> Dict[str, Any]: ...
    @property
    def time(self) -> float: ...
    @property
    def name(self) -> str: ...
    @property
    def kind(self) -> str: ...
    @property
    def method(self) -> str: ...
    @property
    def dt(self) -> float: ...
    @property
    def frames(self) -> int: ...
    @property
    def steps_per_frame(self) -> int: ...
    @property
    def params(self) -> str: ...
    @property
    def choice(self) -> Optional[Dict[str, Any]]: ...
    def reference_error(self) -> Optional[float]: ...
