"""Type stubs of the polydem package (the native module polydem._polydem)."""

from os import PathLike
from typing import Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

__version__: str

ArrayLike = npt.ArrayLike
FloatArray = npt.NDArray[np.float64]
Pose = Tuple[ArrayLike, ArrayLike]
"""(position[3] in m, quaternion[4] as w, x, y, z)."""
StrPath = Union[str, PathLike]

class SceneError(ValueError):
    """A scene that cannot be read or built; the message is the engine's (file:line: field: problem)."""

    path: str
    line: Optional[int]
    field: Optional[str]

class CheckpointError(ValueError):
    """A checkpoint file that cannot be read (not a checkpoint, another version, truncated, corrupt)."""

class StepError(RuntimeError):
    """A step that failed (a non-finite state, an invalid time step); names the body and step."""

class Shape:
    """A bounded convex shape. Mass properties per unit density, in the frame the shape was given in."""

    @property
    def volume(self) -> float:
        """Volume (m³)."""
    @property
    def centroid(self) -> FloatArray:
        """Centroid in the shape's input frame (m), shape (3,)."""
    @property
    def principal_moments(self) -> FloatArray:
        """Principal moments of inertia per unit density (m⁵), ascending, shape (3,)."""
    @property
    def principal_axes(self) -> FloatArray:
        """3×3 array whose column k is the axis of principal_moments[k], in the input frame."""
    @property
    def bounding_radius(self) -> float:
        """Radius of the bounding sphere about the centroid (m)."""

class ConvexPolyhedron(Shape):
    """A convex polyhedron: the convex hull of a point cloud."""

    @staticmethod
    def from_points(points: ArrayLike) -> ConvexPolyhedron:
        """The hull of an (N, 3) array of finite points (N ≥ 4, not coplanar); ValueError otherwise."""
    @property
    def vertices(self) -> FloatArray:
        """Hull vertices in the input frame, shape (N, 3) (a copy)."""
    @property
    def num_faces(self) -> int:
        """Number of (polygonal) faces."""

class Sphere(Shape):
    """A sphere of the given radius (m) centred at its origin."""

    def __init__(self, radius: float) -> None: ...
    @property
    def radius(self) -> float:
        """Radius (m)."""

class Ellipsoid(Shape):
    """An ellipsoid with semi-axes a, b, c (m) along its x, y, z axes."""

    def __init__(self, a: float, b: float, c: float) -> None: ...
    @property
    def semi_axes(self) -> FloatArray:
        """(a, b, c) in metres."""

class ContactResult:
    """Minkowski contact features of a pair (a, b), world frame, normal from a towards b."""

    @property
    def status(self) -> str:
        """'overlap', 'touching' or 'separated'."""
    @property
    def solver(self) -> str:
        """'exact', 'converged', 'fallback_after_max_iterations' or 'fallback_after_degenerate'."""
    @property
    def depth(self) -> float:
        """Minkowski overlap (m), zero unless overlapping."""
    @property
    def distance(self) -> float:
        """Gap (m), zero unless separated."""
    @property
    def normal(self) -> FloatArray:
        """Unit normal from a towards b, shape (3,)."""
    @property
    def point_a(self) -> FloatArray:
        """Contact point on a's surface (m)."""
    @property
    def point_b(self) -> FloatArray:
        """Contact point on b's surface (m)."""
    @property
    def point(self) -> FloatArray:
        """Midpoint of point_a and point_b (m)."""

def contact(
    a: Shape, b: Shape, pose_a: Optional[Pose] = None, pose_b: Optional[Pose] = None
) -> ContactResult:
    """The contact between a at pose_a and b at pose_b (None: identity), as `polydem contact` answers it."""

def contact_batch(
    a: Union[Shape, Sequence[Shape]],
    b: Union[Shape, Sequence[Shape]],
    pose_a: Optional[Tuple[ArrayLike, ArrayLike]] = None,
    pose_b: Optional[Tuple[ArrayLike, ArrayLike]] = None,
) -> dict[str, np.ndarray]:
    """The contacts of n pairs as arrays (status, solver, depth, distance: (n,); normal, point_a, point_b,
    point: (n, 3)). a, b: one Shape for every pair or n Shapes; poses: None or (positions (n, 3),
    quaternions (n, 4) as w, x, y, z). Computed in parallel with the GIL released; equal to contact()."""

class Scene:
    """A scene read and validated by the engine; start Simulations from it."""

    @staticmethod
    def from_toml(path: StrPath) -> Scene:
        """Reads a scene file; SceneError with the engine's message (file, line, field) on failure."""
    @staticmethod
    def from_string(text: str, path: StrPath = "<string>") -> Scene:
        """Builds a scene from TOML text; `path` names it in error messages."""
    @property
    def num_bodies(self) -> int: ...
    @property
    def dt(self) -> float:
        """Time step (s)."""
    @property
    def end_time(self) -> float:
        """End time of the scene (s)."""

class Simulation:
    """A running simulation. Every array returned is a copy: the state belongs to the engine and changes
    at the next step."""

    def __init__(self, scene: Scene) -> None: ...
    @staticmethod
    def from_toml(path: StrPath) -> Simulation: ...
    def step(self, n: int = 1) -> None:
        """Advances n steps in the engine with the GIL released; StepError if a step fails."""
    @property
    def time(self) -> float:
        """Simulated time (s)."""
    @property
    def step_index(self) -> int:
        """Steps done since the start of the scene."""
    @property
    def dt(self) -> float:
        """Time step (s)."""
    @property
    def num_bodies(self) -> int: ...
    @property
    def end_time(self) -> float:
        """End time of the scene (s); step() may go past it."""
    @property
    def end_step(self) -> int:
        """The step index at the scene's end time (the steps `polydem run` does)."""
    @property
    def names(self) -> Sequence[str]: ...
    def positions(self) -> FloatArray:
        """Centre-of-mass positions (m), shape (N, 3), a copy."""
    def velocities(self) -> FloatArray:
        """Velocities (m/s), shape (N, 3), a copy."""
    def orientations(self) -> FloatArray:
        """Unit quaternions (w, x, y, z) of the bodies' input frames, shape (N, 4), a copy."""
    def angular_velocities(self) -> FloatArray:
        """World-frame angular velocities (rad/s), shape (N, 3), a copy."""
    def energy(self) -> dict[str, float]:
        """The energy ledger (J) and its time (s)."""
    def save(self, path: StrPath) -> int:
        """Writes a checkpoint; returns the bytes written."""
    @staticmethod
    def load(path: StrPath) -> Simulation:
        """Restores a checkpoint (from save or polydem run); continues bit for bit."""
    def to_bytes(self) -> bytes:
        """The checkpoint bytes of the state."""
    @classmethod
    def from_bytes(cls, data: bytes) -> Simulation:
        """Restores checkpoint bytes."""
