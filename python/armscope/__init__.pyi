from os import PathLike
from typing import Any, Callable, Optional, Union

import numpy as np
import numpy.typing as npt

ArrayLike = npt.ArrayLike
Frame = Union[str, int]

class ArmscopeError(Exception):
    """What armscope refused: its one-line message, as the command line prints it."""

class Model:
    """A robot's rigid-body model, loaded from its URDF (fixed base; the root link welded to the world).

    The algorithms are Pinocchio's, on the URDF's numbers alone (no joint damping, friction or motor:
    those are the plant's). Each takes one state (arrays of shape (nq,)) or a trajectory of N states
    ((N, nq) arrays), and returns arrays of the matching shape.
    """

    @property
    def urdf(self) -> str:
        """The URDF it was loaded from."""
    def __init__(self, urdf: Union[str, PathLike[str]]) -> None:
        """Load the URDF at ``urdf``; armscope's notices come as warnings, a URDF it cannot use raises ArmscopeError."""
    @property
    def nq(self) -> int:
        """The number of position coordinates (one per revolute, continuous or prismatic joint)."""
    @property
    def nv(self) -> int:
        """The number of velocity coordinates (= nq: a continuous joint's position is its angle)."""
    @property
    def joint_names(self) -> list[str]:
        """The joints' names, in coordinate order."""
    @property
    def frame_names(self) -> list[str]:
        """The frames' names (links and joints), by index."""
    @property
    def lower_position_limit(self) -> npt.NDArray[np.float64]:
        """Each coordinate's lower position limit (rad, or m; -inf where none)."""
    @property
    def upper_position_limit(self) -> npt.NDArray[np.float64]:
        """Each coordinate's upper position limit (rad, or m; inf where none)."""
    @property
    def effort_limit(self) -> npt.NDArray[np.float64]:
        """Each coordinate's effort limit from the URDF (N·m, or N)."""
    def rnea(self, q: ArrayLike, v: ArrayLike, a: ArrayLike) -> npt.NDArray[np.float64]:
        """Inverse dynamics (RNEA): τ = M(q)·a + C(q, v)·v + g(q); (nq,) or (N, nq)."""
    def aba(self, q: ArrayLike, v: ArrayLike, tau: ArrayLike) -> npt.NDArray[np.float64]:
        """Forward dynamics (ABA): the accelerations the torques ``tau`` give; (nq,) or (N, nq)."""
    def mass_matrix(self, q: ArrayLike) -> npt.NDArray[np.float64]:
        """The joint-space mass matrix M(q) (CRBA); (nq, nq) or (N, nq, nq)."""
    def gravity_torque(self, q: ArrayLike) -> npt.NDArray[np.float64]:
        """The generalized gravity g(q): the torque that holds the arm still is +g(q); (nq,) or (N, nq)."""
    def frame_pose(self, q: ArrayLike, frame: Frame) -> npt.NDArray[np.float64]:
        """The frame's pose in the world, a 4×4 homogeneous transform (Pinocchio's oMf); (4, 4) or (N, 4, 4)."""
    def jacobian(self, q: ArrayLike, frame: Frame) -> npt.NDArray[np.float64]:
        """The frame's Jacobian, LOCAL_WORLD_ALIGNED: rows 0–2 linear, 3–5 angular velocity; (6, nq) or (N, 6, nq)."""

class Run:
    """One run's every control step as NumPy arrays, and its summary (the dict --summary-json writes)."""

    t: npt.NDArray[np.float64]
    q: npt.NDArray[np.float64]
    q_target: npt.NDArray[np.float64]
    qd: npt.NDArray[np.float64]
    qd_target: npt.NDArray[np.float64]
    tau: npt.NDArray[np.float64]
    tau_g: npt.NDArray[np.float64]
    tau_limit: npt.NDArray[np.float64]
    saturated: npt.NDArray[np.bool_]
    tool_position: npt.NDArray[np.float64]
    duty: Optional[npt.NDArray[np.float64]]
    current: Optional[npt.NDArray[np.float64]]
    summary: dict[str, Any]

def run(**flags: Any) -> Run:
    """``armscope run`` with its flags by name (``-`` as ``_``), its samples as a Run; files only where asked."""

def simulate(model: Union[Model, str, PathLike[str]], controller: Callable[[float, npt.NDArray[np.float64], npt.NDArray[np.float64]], ArrayLike], **flags: Any) -> Run:
    """Run the model with ``controller(t, q, qd) -> tau`` in place of the PD, through the same motors, limits, plant and recordings."""

class Episode:
    """One recorded episode replayed: its smoothed motion, the torque it needed, what the joints had, the verdicts."""

    episode: int
    t: npt.NDArray[np.float64]
    q: npt.NDArray[np.float64]
    qd: npt.NDArray[np.float64]
    qdd: npt.NDArray[np.float64]
    tau: npt.NDArray[np.float64]
    available: npt.NDArray[np.float64]
    verdicts: list[dict[str, Any]]

def replay(source: Union[str, PathLike[str]], urdf: Union[str, PathLike[str]], **options: Any) -> list[Episode]:
    """``armscope replay``: every episode of a recorded motion replayed into the torque each joint needed."""

def size(**flags: Any) -> dict[str, Any]:
    """``armscope size`` with its flags by name: the dict its size.json holds."""

def batch(manifest: Optional[Union[str, PathLike[str]]] = None, **flags: Any) -> dict[str, Any]:
    """``armscope batch [MANIFEST]`` with its flags by name: the dict its summary.json holds."""

def main() -> None:
    """The ``armscope`` command."""
