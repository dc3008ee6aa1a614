"""Articulated rigid bodies from anim-rigid, with Pinocchio's names and argument order.

Joint order, joint and frame names, the velocity layout and Jacobian rows (linear, angular) are
Pinocchio's. A continuous joint's configuration is its angle here and (cos, sin) in Pinocchio:
`to_pinocchio` / `from_pinocchio` convert. Every array returned is a new float64 array (a copy).
Bad arguments (length, dtype, non-finite entries, indices, a Data of another model) raise
ValueError or TypeError naming the argument.
"""

from typing import Dict, Mapping, Optional, Sequence, Tuple, TypedDict, Union

import numpy as np
import numpy.typing as npt

ArrayLike = npt.ArrayLike
F64 = npt.NDArray[np.float64]

WORLD: str
LOCAL: str
LOCAL_WORLD_ALIGNED: str

class Model:
    """A kinematic tree with inertias and frames (immutable)."""

    @property
    def name(self) -> str: ...
    @property
    def nq(self) -> int: ...
    @property
    def nv(self) -> int: ...
    @property
    def njoints(self) -> int: ...
    @property
    def nframes(self) -> int: ...
    @property
    def names(self) -> list[str]: ...
    @property
    def frame_names(self) -> list[str]: ...
    @property
    def lower_position_limit(self) -> F64: ...
    @property
    def upper_position_limit(self) -> F64: ...
    @property
    def gravity(self) -> F64: ...
    def total_mass(self) -> float: ...
    def get_frame_id(self, name: str) -> int: ...
    def get_joint_id(self, name: str) -> int: ...
    def create_data(self) -> Data: ...

class Data:
    """The workspace of the algorithms for one model."""

    def __init__(self, model: Model) -> None: ...
    @property
    def oMi(self) -> F64:
        """(njoints, 4, 4) joint placements (copy)."""
    @property
    def oMf(self) -> F64:
        """(nframes, 4, 4) frame placements (copy)."""
    @property
    def tau(self) -> F64: ...
    @property
    def ddq(self) -> F64: ...
    @property
    def M(self) -> F64:
        """(nv, nv) mass matrix of the last crba, both triangles (copy)."""
    @property
    def J(self) -> F64:
        """(6, nv) joint Jacobians of the last compute_joint_jacobians (copy)."""

class IkResult(TypedDict):
    q: F64
    success: bool
    error: float
    position_error: float
    rotation_error: float
    iterations: int
    attempts: int

def build_model_from_urdf(
    path: str,
    *,
    floating_base: bool = False,
    mimic: bool = False,
    locked_joints: Optional[Union[Sequence[str], Mapping[str, float]]] = None,
) -> Model:
    """Loads a URDF file (FileNotFoundError if missing, anim.BuildError if malformed)."""

def build_model_from_xml(
    xml: str,
    *,
    floating_base: bool = False,
    mimic: bool = False,
    locked_joints: Optional[Union[Sequence[str], Mapping[str, float]]] = None,
) -> Model: ...
def neutral(model: Model) -> F64: ...
def random_configuration(model: Model, seed: int = 0) -> F64: ...
def integrate(model: Model, q: ArrayLike, v: ArrayLike) -> F64: ...
def difference(model: Model, q0: ArrayLike, q1: ArrayLike) -> F64: ...
def to_pinocchio(model: Model, q: ArrayLike) -> F64: ...
def from_pinocchio(model: Model, q: ArrayLike) -> F64: ...
def pinocchio_nq(model: Model) -> int: ...
def forward_kinematics(model: Model, data: Data, q: ArrayLike) -> None: ...
def update_frame_placements(model: Model, data: Data) -> None: ...
def frames_forward_kinematics(model: Model, data: Data, q: ArrayLike) -> None: ...
def frame_placement(model: Model, data: Data, frame_id: int) -> F64:
    """(4, 4) world placement of a frame (copy)."""
def frame_rotation_translation(model: Model, data: Data, frame_id: int) -> Tuple[F64, F64]: ...
def compute_joint_jacobians(model: Model, data: Data, q: ArrayLike) -> None: ...
def get_frame_jacobian(model: Model, data: Data, frame_id: int, reference_frame: str = "local") -> F64:
    """(6, nv), rows (linear, angular)."""
def compute_frame_jacobian(
    model: Model, data: Data, q: ArrayLike, frame_id: int, reference_frame: str = "local"
) -> F64: ...
def rnea(model: Model, data: Data, q: ArrayLike, v: ArrayLike, a: ArrayLike) -> F64:
    """Inverse dynamics tau = M(q) a + C(q, v) v + g(q), (nv,)."""
def rnea_batch(model: Model, data: Data, q: ArrayLike, v: ArrayLike, a: ArrayLike) -> F64:
    """rnea on the rows of (N, nq), (N, nv), (N, nv) arrays, without the GIL: (N, nv)."""
def nonlinear_effects(model: Model, data: Data, q: ArrayLike, v: ArrayLike) -> F64: ...
def compute_generalized_gravity(model: Model, data: Data, q: ArrayLike) -> F64: ...
def crba(model: Model, data: Data, q: ArrayLike) -> F64:
    """(nv, nv) mass matrix, both triangles."""
def aba(model: Model, data: Data, q: ArrayLike, v: ArrayLike, tau: ArrayLike) -> F64:
    """Forward dynamics ddq, (nv,)."""
def inverse_kinematics(
    model: Model,
    frame_id: int,
    target: ArrayLike,
    q_init: Optional[ArrayLike] = None,
    *,
    tolerance: float = 1e-10,
    max_iterations: int = 100,
    restarts: int = 30,
    seed: int = 0x5EED,
) -> IkResult:
    """Damped least squares to the (4, 4) placement `target`, with random restarts."""
