"""Mesh files from anim-io: OBJ, Gmsh .msh and TetGen in (validated); OBJ, PLY and VTK .vtu out."""

from typing import Optional, Tuple

import numpy as np
import numpy.typing as npt

def read_tri_mesh(path: str) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.int64]]:
    """(vertices (n, 3), triangles (m, 3)); FileNotFoundError, or anim.BuildError for a bad mesh."""
def read_tet_mesh(path: str) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.int64]]:
    """(vertices (n, 3), tets (m, 4))."""
def write_obj(path: str, vertices: npt.ArrayLike, triangles: npt.ArrayLike) -> None: ...
def write_ply(path: str, vertices: npt.ArrayLike, triangles: Optional[npt.ArrayLike] = None) -> None: ...
def write_vtu(
    path: str, vertices: npt.ArrayLike, *, triangles: Optional[npt.ArrayLike] = None, tets: Optional[npt.ArrayLike] = None
) -> None: ...
