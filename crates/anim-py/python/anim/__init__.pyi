from . import fem as fem
from . import flip as flip
from . import fluid as fluid
from . import io as io
from . import mpm as mpm
from . import pbd as pbd
from . import rigid as rigid
from . import scene as scene
from . import skin as skin
from . import springs as springs

__version__: str

class AnimError(Exception):
    """The base of every error a crate of anim reports."""

class BuildError(AnimError):
    """A model, mesh or scene the crate refused (the message names the element or field)."""

class SimulationError(AnimError):
    """A step that failed; the simulation is left as before the step."""

class CheckpointError(AnimError):
    """A checkpoint that could not be read, written or restored."""
