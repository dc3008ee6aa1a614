"""Skinned glTF characters from anim-skin: clips sampled, meshes skinned by LBS or DQS."""

from typing import List, Literal, Optional, Union

import numpy as np
import numpy.typing as npt

class Character:
    @staticmethod
    def load(path: str) -> Character:
        """Loads .gltf or .glb (FileNotFoundError, or anim.BuildError naming the element)."""
    @property
    def warnings(self) -> List[str]: ...
    @property
    def clips(self) -> List[str]: ...
    def clip_end(self, clip: Union[int, str]) -> float: ...
    @property
    def num_joints(self) -> int: ...
    @property
    def num_vertices(self) -> int: ...
    @property
    def triangles(self) -> npt.NDArray[np.int64]: ...
    def pose(
        self, clip: Optional[Union[int, str]] = None, t: float = 0.0, method: Literal["lbs", "dqs"] = "lbs"
    ) -> npt.NDArray[np.float64]:
        """Posed positions of all meshes, (n, 3) float64 (a new array)."""
